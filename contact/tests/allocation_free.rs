//! Storage reuse in the hot loops: refactoring the harmonic-balance dynamic blocks at a new
//! frequency (every corrector iteration of a sweep) and the active-set factorizations of the
//! periodic LCP allocate nothing once their workspaces have reached their sizes.

mod common;

use common::allocations;

#[global_allocator]
static ALLOCATOR: common::CountingAllocator = common::CountingAllocator;

use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent, Residual};
use semismooth_contact::hb::{HbOptions, PenaltyHb, PenaltyHbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::lcp::{
    ActiveSetSolver, FrequencyLcp, FrequencyLcpSolver, MinMapJacobian, PeriodicLcp,
    PeriodicLcpOptions, DEFAULT_ACTIVE_SET_REGULARIZATION,
};
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};

fn modified_rod() -> RodModel {
    let spec = RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    };
    build_rod(&spec).unwrap()
}

/// A deterministic state with contact activity at some samples.
fn state(len: usize) -> Vec<f64> {
    (0..len).map(|i| 0.3 * (0.37 * i as f64).sin()).collect()
}

/// Jacobian, factorization (new frequency: dynamic blocks refactored) and solve at the
/// frequencies `omegas`; returns the allocations made after the first frequency.
fn sweep_frequencies<P>(p: &mut P, omegas: &[f64]) -> u64
where
    P: GeneralizedJacobian<Jacobian = semismooth_contact::hb::HbJacobian> + ParameterDependent,
{
    let x = state(p.dim());
    let mut r = vec![0.0; p.dim()];
    let mut jac = p.new_jacobian();
    let mut solver = StructuredHbSolver::new();
    let mut before = 0;
    for (i, &omega) in omegas.iter().enumerate() {
        if i == 1 {
            before = allocations();
        }
        p.set_parameter(omega);
        p.residual(&x, &mut r).unwrap();
        p.jacobian(&x, &mut jac).unwrap();
        solver.factor(&jac).unwrap();
        solver.solve_in_place(&mut r).unwrap();
    }
    assert_eq!(solver.dynamic_factorizations(), omegas.len() as u64);
    allocations() - before
}

#[test]
fn structured_solver_refactors_at_a_new_frequency_without_allocating() {
    let rod = modified_rod();
    let (model, omega) = (&rod.model, rod.omega());
    let omegas: Vec<f64> = (0..5).map(|i| omega * (0.9 + 0.05 * i as f64)).collect();
    let mut ssn = SsnHb::new(model, omega, &HbOptions::default()).unwrap();
    assert_eq!(sweep_frequencies(&mut ssn, &omegas), 0, "SSN-HB");
    let options = PenaltyHbOptions::for_model(model);
    let mut penalty = PenaltyHb::new(model, omega, &options).unwrap();
    assert_eq!(sweep_frequencies(&mut penalty, &omegas), 0, "penalty HB");
}

#[test]
fn active_set_factorizations_reuse_their_storage() {
    let rod = modified_rod();
    let (model, omega) = (&rod.model, rod.omega());
    let options = PeriodicLcpOptions {
        time_samples: 64,
        ..Default::default()
    };
    let lcp = PeriodicLcp::new(model, omega, options.clone()).unwrap();
    let n = lcp.dim();
    // Warm-up with the largest block (all rows; singular, regularised) and the largest
    // coupling `A_IJ` (half the rows), then other sizes.
    let jacobians: Vec<MinMapJacobian<'_>> = [n, n / 2, n / 3, 20, n / 2, 1, 0, n - 1]
        .iter()
        .map(|&k| MinMapJacobian::new(lcp.matrix(), (0..n).map(|i| i < k).collect()).unwrap())
        .collect();
    let mut solver = ActiveSetSolver::new()
        .with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)
        .unwrap();
    let mut rhs = state(n);
    for jac in &jacobians[..2] {
        solver.factor(jac).unwrap();
        solver.solve_in_place(&mut rhs).unwrap();
    }
    let before = allocations();
    for jac in &jacobians[2..] {
        solver.factor(jac).unwrap();
        solver.solve_in_place(&mut rhs).unwrap();
        assert_eq!(solver.active_count(), jac.active_count());
    }
    assert_eq!(allocations() - before, 0, "min-map active set");

    let kappa = model.contact_stiffness_scale();
    let mut problem = FrequencyLcp::new(model, omega, options, kappa).unwrap();
    let mut jac = problem.new_jacobian();
    let mut solver = FrequencyLcpSolver::new();
    let mut rhs = state(problem.dim());
    // y = (w, z) = (0, z): row i is active where z_i > 0. Three quarters of the nodes
    // first (all of them would make A_II singular), then a quarter.
    let forces = |fraction: usize| -> Vec<f64> {
        let mut y = vec![0.0; 2 * n];
        y[n..n + n * fraction / 4].fill(1.0);
        y
    };
    problem.jacobian(&forces(3), &mut jac).unwrap();
    solver.factor(&jac).unwrap();
    solver.solve_in_place(&mut rhs).unwrap();
    problem.jacobian(&forces(1), &mut jac).unwrap();
    assert_eq!(jac.active_count(), n / 4);
    let before = allocations();
    solver.factor(&jac).unwrap();
    solver.solve_in_place(&mut rhs).unwrap();
    assert_eq!(allocations() - before, 0, "frequency LCP active set");
}
