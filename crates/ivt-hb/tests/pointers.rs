//! A problem behind a pointer is the same problem: `&P`, `Box<P>`,
//! `&dyn PeriodicProblem` and `BoxedProblem` forward every method of
//! `PeriodicProblem`, the overridden ones included. The jobs take
//! `&dyn PeriodicProblem` and run families of `BoxedProblem`s, so a method
//! left to its default there would silently replace a user's override (an
//! analytic Jacobian by differences, a hysteretic law as memoryless).
#![allow(clippy::indexing_slicing)]

use ivt_hb::{BoxedProblem, PeriodicProblem};

/// One DOF whose every method is overridden with an answer its default would
/// not give.
struct Marked {
    matrices: [Vec<f64>; 3],
}

impl PeriodicProblem for Marked {
    fn n_dof(&self) -> usize {
        1
    }
    fn mass(&self) -> &[f64] {
        &self.matrices[0]
    }
    fn damping(&self) -> &[f64] {
        &self.matrices[1]
    }
    fn stiffness(&self) -> &[f64] {
        &self.matrices[2]
    }
    fn nonlinear(&self, x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
        out[0] = 1.0 + x[0];
    }
    fn nonlinear_samples(&self, x: &[f64], _v: &[f64], _theta: &[f64], out: &mut [f64]) {
        out.iter_mut().zip(x).for_each(|(o, x)| *o = 10.0 + x);
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        out[0] = 20.0 + theta;
    }
    fn velocity_dependent(&self) -> bool {
        false
    }
    fn hysteretic(&self) -> bool {
        true
    }
    fn nonlinear_jacobian(&self, _x: &[f64], _v: &[f64], _theta: f64, dg: &mut [f64]) {
        dg.copy_from_slice(&[30.0, 31.0]);
    }
    fn nonlinear_jacobian_samples(&self, _x: &[f64], _v: &[f64], _th: &[f64], dg: &mut [f64]) {
        dg.fill(40.0);
    }
    fn frequency_dependent(&self) -> bool {
        true
    }
    fn nonlinear_samples_at(&self, _x: &[f64], _v: &[f64], _th: &[f64], w: f64, out: &mut [f64]) {
        out.fill(50.0 + w);
    }
    fn nonlinear_jacobian_samples_at(
        &self,
        _x: &[f64],
        _v: &[f64],
        _th: &[f64],
        w: f64,
        dg: &mut [f64],
    ) {
        dg.fill(60.0 + w);
    }
    fn excitation_at(&self, theta: f64, w: f64, out: &mut [f64]) {
        out[0] = 70.0 + theta + w;
    }
}

fn marked() -> Marked {
    Marked {
        matrices: [vec![2.0], vec![0.3], vec![5.0]],
    }
}

/// Every method's answer at two samples, in the trait's order.
fn answers(p: &impl PeriodicProblem) -> Vec<f64> {
    let (x, v, th, w) = ([0.5, 0.25], [0.1, 0.2], [0.0, 1.0], 1.5);
    let mut all = vec![p.n_dof() as f64];
    all.extend(p.mass().iter().chain(p.damping()).chain(p.stiffness()));
    let mut one = [0.0];
    p.nonlinear(&x[..1], &v[..1], 0.3, &mut one);
    all.extend(one);
    let mut two = [0.0; 2];
    p.nonlinear_samples(&x, &v, &th, &mut two);
    all.extend(two);
    p.excitation(0.3, &mut one);
    all.extend(one);
    all.push(f64::from(u8::from(p.velocity_dependent())));
    all.push(f64::from(u8::from(p.hysteretic())));
    p.nonlinear_jacobian(&x[..1], &v[..1], 0.3, &mut two);
    all.extend(two);
    let mut four = [0.0; 4];
    p.nonlinear_jacobian_samples(&x, &v, &th, &mut four);
    all.extend(four);
    all.push(f64::from(u8::from(p.frequency_dependent())));
    p.nonlinear_samples_at(&x, &v, &th, w, &mut two);
    all.extend(two);
    p.nonlinear_jacobian_samples_at(&x, &v, &th, w, &mut four);
    all.extend(four);
    p.excitation_at(0.3, w, &mut one);
    all.extend(one);
    all
}

#[test]
fn every_pointer_to_a_problem_gives_the_problems_own_answers() {
    let own = answers(&marked());
    // The overrides are what is compared: none of them is the default's answer.
    assert_eq!(
        own,
        vec![
            1.0, 2.0, 0.3, 5.0, 1.5, 10.5, 10.25, 20.3, 0.0, 1.0, 30.0, 31.0, 40.0, 40.0, 40.0,
            40.0, 1.0, 51.5, 51.5, 61.5, 61.5, 61.5, 61.5, 71.8
        ]
    );
    let problem = marked();
    assert_eq!(answers(&&problem), own, "&P");
    assert_eq!(answers(&Box::new(marked())), own, "Box<P>");
    let as_dyn: &dyn PeriodicProblem = &problem;
    assert_eq!(answers(&as_dyn), own, "&dyn PeriodicProblem");
    let boxed: BoxedProblem<'_> = Box::new(marked());
    assert_eq!(answers(&boxed), own, "BoxedProblem");
}
