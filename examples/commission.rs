//! The rig loop end to end against a simulated rig (issue #29, README
//! "Commission your rig"): a rig whose motor, gears and output radius differ
//! from Table 1 runs every commissioning sequence (θ_CT sweep, hold, step
//! test, drive cycle; `ivt_sim::commission`, SIL) with realistic sensors; the
//! recording is read back as `ivt rig identify` reads it and identified
//! (Eq. 151 by equation error, 95 % intervals); the identified plant is
//! written as a plant file; the open-loop law is refitted for it and emitted
//! as Rust for the firmware.
//!
//! `cargo run --release --example commission` → `out/commission/`.
//! The command-line form of the same loop is `ivt rig commission --sim
//! --plant-file rig.toml --sensors realistic --out run.mcap`, `ivt rig
//! identify run.mcap --out plant.toml`, then `ivt ol fit --plant-file
//! plant.toml --emit-rust FILE`.

/// The reader of `ivt rig identify` (the command layer's module).
use ivt::cli::commissioning;
use ivt_design::identify::{identify, NAMES};
use ivt_design::open_loop::fit_law;
use ivt_design::steady::IhbOptions;
use ivt_design::sweep::Grid;
use ivt_kin::plant::PlantParams;
use ivt_sim::scene::{PlantSection, PresetName};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::path::Path::new("out/commission");
    std::fs::create_dir_all(out)?;
    // The "rig": Table 1 with a weaker motor, heavier rings and a larger output gear.
    let mut rig = PlantParams::printed();
    rig.k_t *= 0.85;
    rig.k_e *= 0.9;
    rig.j_ring *= 1.25;
    rig.r_u *= 1.2;
    let body = PlantSection::from_params(PresetName::Printed, &rig).to_toml();
    let body: String = body.lines().skip(1).map(|l| format!("{l}\n")).collect();

    let rig_file = out.join("rig.toml");
    std::fs::write(&rig_file, format!("[plant]\n{body}"))?;
    let run = out.join("run.mcap");
    let opts = ivt_sim::commission::CommissionOptions {
        plant: PlantSection::from_file(&rig_file)?,
        sensors: ivt_sim::commission::SensorModel::Realistic,
        ..Default::default()
    };
    ivt_sim::commission::run_sil(&opts, &run)?;
    let id = identify(
        &commissioning::read(&run)?.recording,
        &PlantParams::printed(),
    )?;
    let truth = [
        rig.j_a(),
        rig.j_b(),
        rig.j_c(),
        rig.j_d(),
        rig.motor_damping(),
        rig.motor_gain(),
        rig.load_gain(),
    ];
    println!(
        "{:<14} {:>12} {:>12} {:>26}",
        "", "true", "identified", "95 % interval"
    );
    for ((name, e), t) in NAMES.iter().zip(&id.estimates).zip(truth) {
        println!(
            "{name:<14} {t:>12.5e} {:>12.5e} [{:.5e}, {:.5e}]",
            e.value, e.ci95[0], e.ci95[1]
        );
    }
    if let Some(s) = &id.sweep {
        println!(
            "Fig. 50: K2·T_out = {:.4} rpm/deg → K = {:.1} deg/rpm (Eq. 190)",
            s.k2_t_out, s.k
        );
    }
    let plant = id.plant(&PlantParams::printed());
    let file = out.join("plant.toml");
    std::fs::write(
        &file,
        PlantSection::from_params(PresetName::Printed, &plant).to_toml(),
    )?;
    println!("plant file → {}", file.display());

    // The open-loop law for the identified plant, on a grid around its
    // feasible band for 100 rpm (SPEC §5: V_m from c·ω0/a, a few tenths of a
    // volt wide per N·m of load).
    let grid = Grid {
        v_m: ivt_design::sweep::range(6.8, 0.2, 8.6),
        t_u: ivt_design::sweep::range(2.0, 1.0, 8.0),
        omega0: ivt_design::rpm_to_rad_s(100.0),
    };
    let rep = fit_law(
        &plant,
        &grid,
        ivt_design::fit::PolyForm::Eq158,
        IhbOptions::default(),
        || {},
    )?;
    let rust = ivt_design::fit::emit_rust(
        &rep.law,
        "REFIT",
        "Refitted for the identified rig (examples/commission.rs).",
    );
    std::fs::write(out.join("refit.rs"), rust)?;
    println!(
        "open-loop law refitted on {} feasible points: ω_a error max {:.3} rpm → {}",
        rep.fit.points,
        rep.law_error.max_abs_rpm,
        out.join("refit.rs").display()
    );
    Ok(())
}
