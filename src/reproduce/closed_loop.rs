//! §4.3–4.4: closed-loop scenes (Figs. 43–45 analogues) and the simulated
//! drive cycle (Fig. 51).

use super::{Context, ReproError};

const WHY: &str =
    "not computable (module not yet built): the simulator (branch sim) is not in this build";

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("closed loop: not built");
    for id in ["Fig. 43", "Fig. 44", "Fig. 45", "Fig. 51"] {
        ctx.missing_figure(id, "closed loop", WHY);
    }
    Ok(())
}
