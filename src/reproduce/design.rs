//! §4.2–4.3: IVT steady state, open-loop law refit, stability map
//! (Figs. 38, 39, 40, 42).

use super::{Context, ReproError};

const WHY: &str = "not computable (module not yet built): the IVT design tools (branch design) are not in this build";

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("design: not built");
    for (q, t) in [
        ("r̄ at (6 V, 6 N·m) [m]", "0.0067 (Fig. 39)"),
        ("Eq. 158 coefficients", "Eq. 158"),
        ("Eq. 159 coefficients", "Eq. 159"),
        ("Fig. 42 multiplier (k = 0.01, k2 = 0.02)", "0.7776 (§4.3)"),
        ("Fig. 42 multiplier (k = 0.06, k2 = 0.12)", "0.4871 (§4.3)"),
    ] {
        ctx.not_computable(q, t, WHY);
    }
    for id in ["Fig. 38", "Fig. 39", "Fig. 40", "Fig. 42"] {
        ctx.missing_figure(id, "IVT design", WHY);
    }
    Ok(())
}
