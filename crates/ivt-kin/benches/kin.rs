//! Hot paths of ivt-kin: the ratio functions (called per sample by the
//! simulator and the CLI) and the profile/arc generators.
//! Run: `cargo bench -p ivt-kin`.

use ivt_kin::arcs::{fit_arcs, Arc, ArcOptions, GearProfile, Member};
use ivt_kin::givt::GivtGeometry;
use ivt_kin::ncg::{pitch_profile, GivtNcg, PitchPoint, SgivtNcg};
use ivt_kin::sgivt::SgivtGeometry;

fn main() {
    divan::main();
}

/// Benches `ratio` along a sample stream: θ advances 1 mrad per call.
fn along_theta<R>(b: divan::Bencher, ratio: impl Fn(f64) -> R) {
    let mut t = 0.0;
    b.bench_local(|| {
        t += 0.001;
        ratio(divan::black_box(t))
    });
}

#[divan::bench]
fn sgivt_ratio_eq35(b: divan::Bencher) {
    let g = SgivtGeometry::prototype();
    along_theta(b, |t| g.ratio(t, 0.02));
}

#[divan::bench]
fn givt_module_ratio_eq9(b: divan::Bencher) {
    let g = GivtGeometry::illustrative();
    along_theta(b, |t| g.module_ratio(t, 0.01));
}

#[divan::bench]
fn givt_average_ratio(b: divan::Bencher) {
    let g = GivtGeometry::illustrative();
    b.bench_local(|| g.average_module_ratio(divan::black_box(0.01)));
}

#[divan::bench(args = [361, 3601])]
fn sgivt_pitch_profile(b: divan::Bencher, n: usize) {
    let mut pts = vec![PitchPoint::default(); n];
    b.bench_local(|| pitch_profile(&SgivtNcg, divan::black_box(0.13335), &mut pts));
}

#[divan::bench]
fn givt_ncg_design(b: divan::Bencher) {
    b.bench_local(|| GivtNcg::new(GivtGeometry::illustrative(), divan::black_box(0.01)));
}

#[divan::bench(args = [Member::Driven, Member::Driving])]
fn sgivt_arcs_one_percent(b: divan::Bencher, member: Member) {
    let prof = GearProfile {
        gear: &SgivtNcg,
        centre_distance: 0.13335,
        member,
    };
    let mut arcs = vec![Arc::default(); 512];
    b.bench_local(|| fit_arcs(&prof, &ArcOptions::default(), &mut arcs));
}
