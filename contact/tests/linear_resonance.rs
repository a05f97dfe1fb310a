//! A linear model (no contact, no friction) forced at its first natural frequency with
//! light damping: the response is large, and so is the residual that round-off alone
//! leaves after the one linear solve. Newton stops there: converged, one factorization,
//! and the answer is the direct complex solve of the dynamic stiffness.

mod common;

#[path = "common/chain.rs"]
mod chain;

use semismooth_contact::settings::SolverSettings;
use semismooth_contact::solve::solve;

#[test]
fn a_linear_chain_at_resonance_converges_with_one_factorization() {
    // zeta = 1e-4 at omega_1 under a force of 1e3: a first-harmonic amplitude of about
    // 1e3 / (2 zeta k_1) ~ 1.3e7, where one ulp of the stiffness forces is about 1e-9 and
    // the absolute tolerance 1e-10 cannot be met.
    let mut chain = chain::chain(1.0, 1e-4, [0.0, 1e3]);
    chain.model.contacts.clear();
    let settings = SolverSettings {
        estimate_error: false,
        ..SolverSettings::default()
    };
    let omega = chain.omega_1;
    let solution = solve(&chain, omega, &settings, None).expect("the solve runs");
    assert!(
        solution.converged(),
        "{:?} after {} iterations, |F| = {:e}",
        solution.termination,
        solution.iterations,
        solution.residual_norm
    );
    assert_eq!(
        solution.counters.factorizations, 1,
        "{:?}",
        solution.counters
    );
    // The direct solve: u(t) = Re z cos(w t) - Im z sin(w t) at the observed dof. Both
    // solves are backward stable on a matrix of condition number about 1 / (2 zeta) = 5e3:
    // they agree to 1e-16 x 5e3 relative, 1e-11 leaves a margin of 20.
    let z = common::exact_linear(&chain.model, omega)[chain.observed_dof];
    let amplitude = z.norm();
    let difference = solution
        .times
        .iter()
        .zip(&solution.observed)
        .map(|(t, u)| (u - (z.re * (omega * t).cos() - z.im * (omega * t).sin())).abs())
        .fold(0.0f64, f64::max);
    assert!(
        difference <= 1e-11 * amplitude,
        "{difference:e} against an amplitude of {amplitude:e}"
    );
}
