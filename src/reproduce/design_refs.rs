//! What the §4.2–4.3 reproduction cites in both of its modules (design.rs,
//! design_maps.rs): the SPEC §5 finding, the test behind it, and the figure id
//! on a plant preset.

use ivt_kin::plant::PlantPreset;

/// SPEC §5's finding on the printed plant.
pub(super) const SPEC5: &str =
    "SPEC §5: the printed u_ol (Eq. 158) does not hold 100 rpm on the printed \
plant (Eq. 151 + Table 1); 100 rpm needs V_m in the band [7.87, 7.87 + 0.154 T_U] V";

/// The test showing that the printed plant's 100-rpm band excludes the thesis's points.
pub(super) const BAND_TEST: &str =
    "crates/ivt-design/tests/ivt_design.rs::verdicts_follow_the_band";

/// Figure id of a thesis figure on a preset (`printed` keeps the bare id).
pub(super) fn fig_id(base: &str, preset: PlantPreset) -> String {
    match preset {
        PlantPreset::Printed => base.to_string(),
        _ => format!("{base} ({})", preset.name()),
    }
}
