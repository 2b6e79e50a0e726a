//! Scratch: run a scene file and print its summary (and, with a second
//! argument N, every N-th logged plant/control sample as t, ω_a, r, r_ol, r_d).
fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("scene path");
    let every: usize = args.next().map_or(0, |s| s.parse().unwrap());
    let scene = ivt_sim::scene::Scene::load(std::path::Path::new(&path)).unwrap();
    let res = ivt_sim::run::Simulation::new(&scene).run().unwrap();
    if every > 0 {
        if let (Some(p), Some(c)) = (&res.channels.plant, &res.channels.control) {
            for (a, b) in p.iter().zip(c).step_by(every) {
                println!(
                    "{:8.3} wa={:9.5} w={:9.5} r={:.6} rol={:.6} rd={:.6} V={:.3} T={:.2} sat={}",
                    a.t,
                    a.omega_a,
                    a.omega,
                    a.r,
                    b.out.r_ol,
                    b.out.r_d,
                    a.v_m,
                    a.t_u,
                    b.out.saturated
                );
            }
        }
    }
    println!("{}", serde_json::to_string_pretty(&res.summary).unwrap());
}
