//! The branches layer: families of orbits followed by the path engine
//! (`ivt_path`, pseudo-arclength Eq. 68–77) and the events on them. The HB
//! residual in any parameter as a `Branch` ([`family`]), the frequency
//! response ([`frc`]), limit cycles with ω unknown ([`autonomous`]) and their
//! branch from a Hopf point ([`cycle_branch`]), backbones and damped modes
//! ([`backbone`], [`damped`]), curves of folds, period doublings and
//! Neimark–Sacker points in two parameters ([`codim2`]), the Mathieu–Duffing
//! cascade ([`mathieu`]), branch switching ([`switching`]), quasi-periodic tori
//! bifurcating from a Neimark–Sacker point ([`torus`]), and the events of
//! a family branch with their Floquet multipliers ([`events`]). It uses the
//! problem, orbit and stability layers and the path engine.

pub mod autonomous;
pub mod backbone;
pub mod codim2;
pub mod cycle_branch;
pub mod damped;
pub mod events;
pub mod family;
pub mod frc;
pub mod mathieu;
pub mod switching;
pub mod torus;
