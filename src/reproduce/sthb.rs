//! Chapter 3.3: string frequency-response curves (Figs. 34–36).

use super::{Context, ReproError};

const WHY: &str =
    "not computable (module not yet built): the STHB engine (branch sthb) is not in this build";

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("sthb: not built");
    for id in ["Fig. 34", "Fig. 35", "Fig. 36"] {
        ctx.missing_figure(id, "string frequency-response curves", WHY);
    }
    Ok(())
}
