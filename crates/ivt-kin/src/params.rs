//! Every number a user sets, described once: its key, unit, physical range
//! and whether the controller holds it as an `f32` ([`KEYS`]), and the CLI
//! flags and Python arguments that set the same quantity ([`ALIASES`]).
//!
//! Every boundary checks its numbers here — a scene's sections
//! (`ivt_sim::scene`), [`PlantParams::validate`](crate::plant::PlantParams::validate),
//! the CLI's flags and ivt-py's arguments — so a range and its message are
//! written once: a refusal ([`Refused`]) reads `= 1e300 mm/rad does not fit
//! the controller's f32 …` or `= 3600.0000001 deg is outside [0, 3600] deg`,
//! and each boundary puts the name the user typed in front (`` `controller.k_mm_per_rad` ``,
//! `--k`, `` argument `k` ``). Values are shown as typed ([`Typed`]: `1e300`,
//! `3600.0000001`, never 300 digits or a converted unit).
//!
//! The module lives in ivt-kin, the lowest crate every boundary depends on
//! (ivt-sim, ivt-design, the CLI and ivt-py all use it; ivt-num would hold it
//! too, but ivt-py and the CLI reach it only through ivt-kin's plant and the
//! plant parameters are ivt-kin's own). It is `no_std` and allocation-free.
//!
//! The ranges are physical bounds on the bench of the thesis (§4.4: a 12 V
//! motor, a brake of a few N·m, ω0 of 100 rpm, Table 1's plant) widened by
//! orders of magnitude; they refuse what no rig can mean (`t_u = 1e300`) and
//! what the integrator cannot honour (`rtol = 1e-300`: below ~1e-14 DP5's
//! error estimate is round-off, Hairer–Nørsett–Wanner §II.4), not unusual
//! but valid studies.

use core::fmt;

/// One bound of a [`Key`]'s range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// The value may equal the bound.
    Closed(f64),
    /// The value must differ from the bound.
    Open(f64),
}

impl Bound {
    /// The bound's value.
    #[must_use]
    pub const fn value(self) -> f64 {
        match self {
            Self::Closed(v) | Self::Open(v) => v,
        }
    }
}

/// A user-settable number: its key, what it measures, what it may be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// Dotted key path: the scene key (`controller.k_mm_per_rad`;
    /// `inputs.v_m[]` for a profile's values), `plant.<field>` for a
    /// [`PlantParams`](crate::plant::PlantParams) field, or a path of its own
    /// for a quantity no scene sets (`kin.theta_ct_deg`).
    pub name: &'static str,
    /// Unit as printed in messages (empty for a pure number).
    pub unit: &'static str,
    /// Lower bound.
    pub min: Bound,
    /// Upper bound.
    pub max: Bound,
    /// The controller (ivt-ctrl, firmware) holds it as an `f32`: it must be
    /// finite there too, and not flush a non-zero value to 0.
    pub f32: bool,
    /// A scene sets it under [`Self::name`].
    pub scene: bool,
}

/// A scene key.
const fn scene(name: &'static str, unit: &'static str, min: Bound, max: Bound, f32: bool) -> Key {
    Key {
        name,
        unit,
        min,
        max,
        f32,
        scene: true,
    }
}

/// A plant parameter (`plant.<field>` of a scene, a plant file and
/// [`PlantParams`](crate::plant::PlantParams)): f64 only, a closed ceiling.
const fn plant(name: &'static str, unit: &'static str, min: Bound, max: f64) -> Key {
    scene(name, unit, min, Closed(max), false)
}

/// A key no scene sets (CLI flags and Python arguments only).
const fn other(name: &'static str, unit: &'static str, range: (Bound, Bound), f32: bool) -> Key {
    Key {
        scene: false,
        ..scene(name, unit, range.0, range.1, f32)
    }
}

use Bound::{Closed, Open};

/// Longest simulated time a scene may ask for \[s\]: 10⁶ s (11.6 days) at the
/// measured ≈ 20× real time of the default scene is ~14 h of wall time.
pub const MAX_DURATION_S: f64 = 1e6;
const T_MAX: f64 = MAX_DURATION_S;
/// Largest inertia \[kg·m²\] and mass \[kg\] of a plant parameter: 10⁴× the
/// largest of Table 1.
const J_MAX: f64 = 1e3;

/// Every user-settable number of the IVT model and controller except the
/// integers (`encoder.ppr`, counts, orders: their boundaries check them as
/// counts) and the eccentricities bounded by the plant's own r_max
/// (`initial.r`, `controller.r_schedule[]`).
#[rustfmt::skip]
pub const KEYS: &[Key] = &[
    scene("duration_s", "s", Open(0.0), Closed(T_MAX), false),
    scene("inputs.v_m[].t", "s", Closed(0.0), Closed(T_MAX), false),
    scene("inputs.v_m[]", "V", Closed(-1e3), Closed(1e3), true),
    scene("inputs.t_u[].t", "s", Closed(0.0), Closed(T_MAX), false),
    scene("inputs.t_u[]", "N·m", Closed(0.0), Closed(1e3), true),
    scene("initial.theta", "rad", Closed(-1e6), Closed(1e6), false),
    scene("initial.omega", "rad/s", Closed(0.0), Closed(1e4), false),
    scene("integrator.rtol", "", Closed(1e-14), Open(1.0), false),
    scene("integrator.atol", "", Closed(1e-14), Open(1.0), false),
    scene("integrator.dtheta", "rad", Closed(1e-9), Closed(1.0), false),
    scene("integrator.omega_handover", "rad/s", Open(0.0), Closed(1e4), false),
    scene("encoder.f_timer_hz", "Hz", Open(0.0), Closed(1e9), true),
    scene("encoder.jitter_s", "s", Closed(0.0), Closed(1.0), false),
    scene("sensors.period_s", "s", Closed(1e-7), Closed(T_MAX), false),
    scene("sensors.v_m_noise", "V", Closed(0.0), Closed(1e3), false),
    scene("sensors.v_m_quantum", "V", Closed(0.0), Closed(1e3), false),
    scene("sensors.t_u_noise", "N·m", Closed(0.0), Closed(1e3), false),
    scene("sensors.t_u_quantum", "N·m", Closed(0.0), Closed(1e3), false),
    scene("stepper.steps_per_rev", "", Open(0.0), Closed(1e6), true),
    scene("stepper.max_speed", "steps/s", Open(0.0), Closed(1e7), true),
    scene("stepper.accel", "steps/s²", Open(0.0), Closed(1e9), true),
    scene("stepper.miss_prob", "", Closed(0.0), Closed(1.0), false),
    // ω0: the thesis's 100 rpm widened by three orders of magnitude below;
    // slower, a pulse of the coarsest encoder takes longer than any stall
    // timeout a rig would run with, and 1e-30 rpm is no set speed at all.
    scene("controller.omega0_rpm", "rpm", Closed(0.1), Open(1e4), true),
    scene("controller.k_mm_per_rad", "mm/rad", Closed(-1e6), Closed(1e6), true),
    scene("controller.k2_mm_per_rad", "mm/rad", Closed(-1e6), Closed(1e6), true),
    scene("controller.k_prop_deg_per_rpm", "deg/rpm", Closed(-1e6), Closed(1e6), true),
    scene("controller.prop_period_s", "s", Open(0.0), Closed(1e3), true),
    scene("controller.r_schedule[].t", "s", Closed(0.0), Closed(T_MAX), false),
    scene("metrics.from_s", "s", Closed(0.0), Closed(T_MAX), false),
    scene("metrics.band", "", Open(0.0), Open(1.0), false),
    scene("metrics.static_window_s", "s", Open(0.0), Closed(T_MAX), false),
    scene("outputs.max_bytes", "bytes", Open(0.0), Closed(1e15), false),
    // Table 1 (PlantParams): non-negative where 0 neglects the term; where a
    // zero divides or is no machine, at least Table 1's value / 1e4 (the
    // ceilings are ~1e4× it), so that 1e-300 Ω is refused by name instead of
    // failing later as a NaN.
    plant("plant.r_a", "Ω", Closed(1e-4), 1e3),
    plant("plant.k_e", "V·s/rad", Closed(1e-5), 1e3),
    plant("plant.k_t", "N·m/A", Closed(1e-5), 1e3),
    plant("plant.l_a", "H", Closed(0.0), 1e3),
    plant("plant.j_n1", "kg·m²", Closed(1e-7), J_MAX),
    plant("plant.j_n2", "kg·m²", Closed(1e-7), J_MAX),
    plant("plant.j_inshaft", "kg·m²", Closed(0.0), J_MAX),
    plant("plant.j_carrier", "kg·m²", Closed(0.0), J_MAX),
    plant("plant.j_ring", "kg·m²", Closed(0.0), J_MAX),
    plant("plant.j_crk", "kg·m²", Closed(1e-7), J_MAX),
    plant("plant.m_r", "kg", Closed(0.0), J_MAX),
    plant("plant.m_dr", "kg", Closed(0.0), J_MAX),
    plant("plant.j_u", "kg·m²", Closed(0.0), J_MAX),
    plant("plant.r_u", "m", Closed(1e-5), 1e2),
    plant("plant.g", "m/s²", Closed(0.0), 1e3),
    plant("plant.sun_to_planet", "", Closed(1e-3), 1e3),
    plant("plant.r_max", "m", Closed(1e-6), 1e2),
    // Set by the CLI and Python only.
    other("kin.theta_ct_deg", "deg", (Closed(0.0), Closed(3600.0)), false),
    other("kin.givt_r_mm", "mm", (Closed(0.0), Closed(1e3)), false),
    other("kin.givt_l1_mm", "mm", (Open(0.0), Closed(1e3)), false),
    other("kin.givt_r_output_mm", "mm", (Open(0.0), Closed(1e3)), false),
    other("kin.arc_tolerance", "", (Open(0.0), Open(1.0)), false),
    other("kin.arc_corner_deg", "deg", (Open(0.0), Closed(90.0)), false),
    other("kin.r_sun", "", (Open(0.0), Closed(1e6)), false),
    other("kin.r_planet", "", (Open(0.0), Closed(1e6)), false),
    other("controller.omega0", "rad/s", (Closed(0.01), Open(1e3)), true),
    other("controller.k_si", "m·s/rad²", (Closed(-1e3), Closed(1e3)), true),
    other("controller.k2_si", "m·s/rad²", (Closed(-1e3), Closed(1e3)), true),
    other("controller.k_prop_si", "m·s/rad", (Closed(-1e3), Closed(1e3)), true),
    other("controller.stall_timeout_s", "s", (Open(0.0), Closed(1e3)), true),
    other("budget.max_events", "", (Open(0.0), Closed(1e15)), false),
];

/// Which boundary an [`Alias`] belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Boundary {
    /// A flag of the `ivt` command line.
    Cli,
    /// An argument of the Python package `ivt`.
    Python,
}

/// A CLI flag or Python argument that sets the quantity of [`KEYS`]' `key`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Alias {
    /// Where the name is typed.
    pub boundary: Boundary,
    /// The name as typed (`--omega0-rpm`, `omega0_rpm`).
    pub name: &'static str,
    /// The key whose unit and range it has.
    pub key: &'static str,
}

const fn cli(name: &'static str, key: &'static str) -> Alias {
    Alias {
        boundary: Boundary::Cli,
        name,
        key,
    }
}

const fn py(name: &'static str, key: &'static str) -> Alias {
    Alias {
        boundary: Boundary::Python,
        name,
        key,
    }
}

/// The CLI flags and Python arguments of [`KEYS`]' quantities: `ivt kin`
/// (θ_CT, the GIVT's lengths in mm, the arc fit, the direction module),
/// `ivt ol`, `ivt stability(-map)`, `ivt ctrl replay`, `ivt sim`, `ivt rig
/// commission` and `ivt rig record`;
/// `ivt.kin.Plant`, `ivt.kin.direction`, `ivt.design`, `ivt.ctrl.Controller`. (A scene passed to
/// `ivt sim` or `ivt.sim.run` is checked under its scene keys; a plant file
/// under `plant.<field>`.) Gains under `--si`/`si=True` and the controller's
/// own SI keywords are the `_si` keys.
#[rustfmt::skip]
pub const ALIASES: &[Alias] = &[
    cli("--theta-ct", "kin.theta_ct_deg"),
    cli("--r-mm", "kin.givt_r_mm"),
    cli("--l1-mm", "kin.givt_l1_mm"),
    cli("--r-output-mm", "kin.givt_r_output_mm"),
    cli("--tolerance", "kin.arc_tolerance"),
    cli("--corner-deg", "kin.arc_corner_deg"),
    cli("--r-sun", "kin.r_sun"),
    cli("--r-planet", "kin.r_planet"),
    cli("--vm", "inputs.v_m[]"),
    cli("--tu", "inputs.t_u[]"),
    cli("--vm-from", "inputs.v_m[]"),
    cli("--vm-to", "inputs.v_m[]"),
    cli("--tu-from", "inputs.t_u[]"),
    cli("--tu-to", "inputs.t_u[]"),
    cli("--omega0-rpm", "controller.omega0_rpm"),
    cli("--k", "controller.k_mm_per_rad"),
    cli("--k2", "controller.k2_mm_per_rad"),
    cli("--k", "controller.k_si"),
    cli("--k2", "controller.k2_si"),
    cli("--k-prop", "controller.k_prop_deg_per_rpm"),
    cli("--prop-period", "controller.prop_period_s"),
    cli("--f-timer", "encoder.f_timer_hz"),
    cli("--f-timer-hz", "encoder.f_timer_hz"),
    cli("--stall-timeout", "controller.stall_timeout_s"),
    cli("--max-events", "budget.max_events"),
    py("r_sun", "kin.r_sun"),
    py("r_planet", "kin.r_planet"),
    py("v_m", "inputs.v_m[]"),
    py("t_u", "inputs.t_u[]"),
    py("omega0_rpm", "controller.omega0_rpm"),
    py("k", "controller.k_mm_per_rad"),
    py("k2", "controller.k2_mm_per_rad"),
    py("k", "controller.k_si"),
    py("k2", "controller.k2_si"),
    py("f_timer_hz", "encoder.f_timer_hz"),
    py("omega0", "controller.omega0"),
    py("k_prop", "controller.k_prop_si"),
    py("prop_period_s", "controller.prop_period_s"),
    py("stepper_max_speed", "stepper.max_speed"),
    py("stepper_accel", "stepper.accel"),
    py("stall_timeout_s", "controller.stall_timeout_s"),
    py("r_a", "plant.r_a"),
    py("k_e", "plant.k_e"),
    py("k_t", "plant.k_t"),
    py("l_a", "plant.l_a"),
    py("j_n1", "plant.j_n1"),
    py("j_n2", "plant.j_n2"),
    py("j_inshaft", "plant.j_inshaft"),
    py("j_carrier", "plant.j_carrier"),
    py("j_ring", "plant.j_ring"),
    py("j_crk", "plant.j_crk"),
    py("m_r", "plant.m_r"),
    py("m_dr", "plant.m_dr"),
    py("j_u", "plant.j_u"),
    py("r_u", "plant.r_u"),
    py("g", "plant.g"),
    py("sun_to_planet", "plant.sun_to_planet"),
    py("r_max", "plant.r_max"),
];

/// The description of `name` (None for a key not in [`KEYS`]).
#[must_use]
pub fn find(name: &str) -> Option<&'static Key> {
    KEYS.iter().find(|k| k.name == name)
}

/// Why a value was refused, without the name it was given under (each
/// boundary puts that in front): `= 1e300 mm/rad is outside [-1e6, 1e6] mm/rad`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refused {
    /// The description the value failed; None when the boundary asked for
    /// a key or alias that [`KEYS`]/[`ALIASES`] do not describe (a bug the
    /// unit tests rule out).
    pub key: Option<&'static Key>,
    /// The value as given.
    pub value: f64,
}

impl Key {
    /// `value` is finite, fits the controller's f32 where it must, and lies
    /// in the range.
    ///
    /// # Errors
    /// [`Refused`] with this key and the value.
    pub fn check(&'static self, value: f64) -> Result<(), Refused> {
        let fits = !self.f32 || fits_f32(value);
        let above = match self.min {
            Closed(m) => value >= m,
            Open(m) => value > m,
        };
        let below = match self.max {
            Closed(m) => value <= m,
            Open(m) => value < m,
        };
        if fits && value.is_finite() && above && below {
            Ok(())
        } else {
            Err(Refused {
                key: Some(self),
                value,
            })
        }
    }
}

/// Check `value` against key `name` of [`KEYS`].
///
/// # Errors
/// [`Refused`]: out of range, or `name` not in [`KEYS`].
pub fn check(name: &str, value: f64) -> Result<(), Refused> {
    match find(name) {
        Some(key) => key.check(value),
        None => Err(Refused { key: None, value }),
    }
}

/// Check `value`, given under `name` at `boundary`, against `key`: the
/// alias must be one of [`ALIASES`], so that every flag and argument is
/// described in the one table.
///
/// # Errors
/// As [`check`]; also for an alias not in [`ALIASES`].
pub fn check_as(boundary: Boundary, name: &str, key: &str, value: f64) -> Result<(), Refused> {
    let listed = ALIASES
        .iter()
        .any(|a| a.boundary == boundary && a.name == name && a.key == key);
    if listed {
        check(key, value)
    } else {
        Err(Refused { key: None, value })
    }
}

impl fmt::Display for Refused {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Some(key) = self.key else {
            return write!(
                f,
                "= {} has no description in ivt_kin::params",
                Typed(self.value)
            );
        };
        let unit = Unit(key.unit);
        let shown = Typed(self.value);
        if key.f32 && !fits_f32(self.value) {
            return write!(f, "= {shown}{unit} {NOT_F32}");
        }
        let lo = if matches!(key.min, Closed(_)) {
            '['
        } else {
            '('
        };
        let hi = if matches!(key.max, Closed(_)) {
            ']'
        } else {
            ')'
        };
        let (min, max) = (Typed(key.min.value()), Typed(key.max.value()));
        write!(f, "= {shown}{unit} is outside {lo}{min}, {max}{hi}{unit}")
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Refused {}

/// A unit after a number: ` mm/rad`, or nothing for a pure number.
struct Unit(&'static str);

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            Ok(())
        } else {
            write!(f, " {}", self.0)
        }
    }
}

/// A value spelled as a person types it: the shorter of the plain and the
/// exponent form (both round-trip exactly), the plain one unless the
/// exponent saves more than two characters: `0.01`, `3600.0000001`, `1e300`,
/// `1e-300`, `1e6` — never 300 digits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Typed(pub f64);

/// Counts the bytes a `Display` would write (no allocation).
struct Len(usize);

impl fmt::Write for Len {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0 += s.len();
        Ok(())
    }
}

impl fmt::Display for Typed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use fmt::Write as _;
        let (mut plain, mut exp) = (Len(0), Len(0));
        write!(plain, "{}", self.0)?;
        write!(exp, "{:e}", self.0)?;
        if plain.0 <= exp.0 + 2 {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// What is wrong with a value [`fits_f32`] refuses.
pub const NOT_F32: &str =
    "does not fit the controller's f32 (finite, |v| in [1.1754944e-38, 3.4028235e38] or 0)";

/// `value` as an `f32` is finite, and not flushed to 0 unless it is 0.
#[must_use]
pub fn fits_f32(value: f64) -> bool {
    let single = value as f32;
    single.is_finite() && (value == 0.0 || single != 0.0)
}

#[cfg(test)]
#[path = "params_tests.rs"]
mod tests;
