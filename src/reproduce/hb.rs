//! Chapter 3.2: Duffing (Figs. 28–29, IHB timings), Mathieu–Duffing
//! (Figs. 30–33, A0 of §3.2.5, β1/β2/β4).

use super::{Context, ReproError};

const WHY: &str =
    "not computable (module not yet built): the HB engine (branch hb) is not in this build";

pub(crate) fn run(ctx: &mut Context) -> Result<(), ReproError> {
    ctx.step("hb: not built");
    for (q, t) in [
        ("A0 (§3.2.5)", "§3.2.5"),
        ("β1", "4.825 (§3.2.5)"),
        ("β2", "5.194 (§3.2.5)"),
        ("β4", "5.253 (§3.2.5)"),
        ("IHB time, classic [s]", "0.25 s (§3.2.4)"),
        ("IHB time, modified [s]", "0.003 s (§3.2.4)"),
    ] {
        ctx.not_computable(q, t, WHY);
    }
    for id in [
        "Fig. 28", "Fig. 29", "Fig. 30", "Fig. 31", "Fig. 32", "Fig. 33",
    ] {
        ctx.missing_figure(id, "harmonic balance", WHY);
    }
    Ok(())
}
