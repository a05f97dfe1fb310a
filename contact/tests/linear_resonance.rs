//! A linear model (no contact, no friction) forced at its first natural frequency with
//! light damping: the response is large, and so is the residual that round-off alone
//! leaves after the one linear solve. Newton stops there: converged, one factorization,
//! and the answer is the direct complex solve of the dynamic stiffness.

mod common;

#[path = "common/chain.rs"]
mod chain;

use semismooth_contact::settings::{Method, SolverSettings, SweepSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::sweep::frequency_response;

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

/// The chain forced by a unit load on its free mass with a stop `1e16` away, far beyond any
/// response (in proportion: a stiffness of 1e8 N/m, a load of 1 N and a gap of 1e3 m less
/// a factor 1e5, as an imported model in SI units with an obstacle placed out of reach): the
/// HB residual at the zero guess is about 1, while a round-off floor scaled by the gap
/// (`eps max K_ii sqrt(n) g`, above 4 here) would pass the zero guess as a solution.
fn chain_with_a_distant_stop() -> semismooth_contact::model::Structure {
    chain::chain(1e16, 0.05, [0.0, 1.0])
}

#[test]
fn a_contact_that_never_closes_leaves_the_linear_response_at_one_frequency() {
    let chain = chain_with_a_distant_stop();
    let settings = SolverSettings {
        estimate_error: false,
        ..SolverSettings::default()
    };
    for ratio in [0.6, 1.0, 1.4] {
        let omega = ratio * chain.omega_1;
        let solution = solve(&chain, omega, &settings, None).expect("the solve runs");
        assert!(solution.converged(), "{:?}", solution.termination);
        // Backward-stable solves of a system of condition about 1 / (2 zeta) = 10: they
        // agree to well below 1e-12 of the amplitude.
        let (difference, amplitude) =
            common::linear_history_error(&chain.model, chain.observed_dof, &solution);
        assert!(amplitude > 1e-7, "amplitude {amplitude:e}");
        assert!(
            difference <= 1e-12 * amplitude,
            "omega/omega_1 = {ratio}: {difference:e} against an amplitude of {amplitude:e}"
        );
    }
}

#[test]
fn a_sweep_beside_a_contact_that_never_closes_is_the_linear_response_at_every_point() {
    let chain = chain_with_a_distant_stop();
    let settings = common::sweep_solver(Method::SsnHb, 5);
    let sweep = SweepSettings::new(0.5, 1.5);
    let response = frequency_response(&chain, &settings, &sweep, None).expect("the sweep runs");
    assert!(response.converged(), "{}", response.termination);
    assert!(
        response.points.len() > 10,
        "{} points",
        response.points.len()
    );
    let (n, dof) = (chain.model.dofs(), chain.observed_dof);
    for point in &response.points {
        let z = common::exact_linear(&chain.model, point.omega)[dof];
        // Harmonic 1 of the observed dof: cosine coefficient Re z, sine coefficient -Im z.
        let computed = [point.state[n + dof], -point.state[2 * n + dof]];
        // Each point is a Newton fixed point at 0.1 x the tolerance 1e-10 (1e-11 of the
        // unit load) on a system of condition about 10: 1e-8 relative leaves a margin of
        // 100. A point passed at the zero guess would be 100 % off.
        let error = (computed[0] - z.re).hypot(computed[1] - z.im) / z.norm();
        assert!(
            error <= 1e-8,
            "omega = {}: harmonic 1 {computed:?} against the linear {z}",
            point.omega
        );
    }
}
