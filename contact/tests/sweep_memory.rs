//! A sweep that keeps only the contact forces of its points (`StateStorage::ContactForces`)
//! against the same sweep keeping full states: what it stores per point, and that its
//! outputs are the full sweep's (the frequencies, observed extremes and folds bit for bit;
//! the full states it recovers, and what is read from them, to the corrector's residual).

#[path = "common/chain.rs"]
mod chain;
mod common;

use common::{canonical, refined, sweep_solver};
use semismooth_contact::model::Structure;
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::{Method, SolverSettings, SweepSettings};
use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
use semismooth_contact::sweep::{
    frequency_response_storing, FrequencyResponse, StateRecovery, StateStorage,
};

/// The sweep of `structure` with `settings` over `[from, to]` `omega_1`, storing `storage`.
fn sweep(
    structure: &Structure,
    settings: &SolverSettings,
    (from, to): (f64, f64),
    storage: StateStorage,
) -> FrequencyResponse {
    let range = SweepSettings::new(from, to);
    let r = frequency_response_storing(structure, settings, &range, storage, None).unwrap();
    assert!(r.converged(), "{}", r.termination);
    r
}

/// The largest entry of `x` in absolute value.
fn largest(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// The branch's frequencies, observed extremes, amplitudes, corrector iterations, folds and
/// zigzags are the same numbers in both sweeps (they are taken from the continuation's
/// state before it is reduced).
fn assert_same_branch(full: &FrequencyResponse, compact: &FrequencyResponse) {
    assert_eq!(full.points.len(), compact.points.len());
    for (a, b) in full.points.iter().zip(&compact.points) {
        assert_eq!(a.omega.to_bits(), b.omega.to_bits());
        assert_eq!(a.observed_max.to_bits(), b.observed_max.to_bits());
        assert_eq!(a.observed_min.to_bits(), b.observed_min.to_bits());
        assert_eq!(a.amplitude.to_bits(), b.amplitude.to_bits());
        assert_eq!(a.iterations, b.iterations);
    }
    assert_eq!(full.folds, compact.folds);
    assert_eq!(full.fold_indices, compact.fold_indices);
    assert_eq!(full.corner_folds, compact.corner_folds);
    assert_eq!(full.corner_fold_indices, compact.corner_fold_indices);
}

/// The full states recovered from the contact forces against the full sweep's, relative to
/// the largest coefficient of each state; returns the largest difference.
fn recovered_state_difference(
    structure: &Structure,
    settings: &SolverSettings,
    full: &FrequencyResponse,
    compact: &FrequencyResponse,
) -> f64 {
    let mut states = StateRecovery::new(structure, settings, compact);
    let mut worst = 0.0f64;
    for (i, point) in full.points.iter().enumerate() {
        let recovered = states.state(i).unwrap();
        assert_eq!(recovered.len(), point.state.len());
        let scale = largest(&point.state);
        let difference = (recovered.iter().zip(&point.state))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        worst = worst.max(difference / scale);
    }
    worst
}

#[test]
fn a_contact_force_sweep_of_a_2000_dof_rod_stores_m_2h_plus_1_numbers_a_point_with_the_same_branch()
{
    // The modified-mass rod (massless contact node) refined to 2,000 elements, forced
    // strongly enough (p0 = 0.2) for an overhang with two folds.
    let spec = refined(2000, 0.5);
    let rod = build_rod(&RodSpec {
        amplitude: 0.2,
        ..spec
    })
    .unwrap();
    let h = 20;
    let settings = sweep_solver(Method::SsnHb, h);
    let full = sweep(&rod, &settings, (0.8, 1.6), StateStorage::Full);
    let compact = sweep(&rod, &settings, (0.8, 1.6), StateStorage::ContactForces);
    assert_eq!(full.state_storage, StateStorage::Full);
    assert_eq!(compact.state_storage, StateStorage::ContactForces);

    // Memory: m (2H + 1) numbers a point against (2H + 1)(N + m).
    let (n, m, points) = (
        rod.model.dofs(),
        rod.model.contact_count(),
        full.points.len(),
    );
    assert!(!full.folds.is_empty(), "the overhang's folds");
    assert_eq!(full.stored_state_numbers(), points * (2 * h + 1) * (n + m));
    assert_eq!(compact.stored_state_numbers(), points * (2 * h + 1) * m);
    for point in &compact.points {
        assert_eq!(point.state.len(), m * (2 * h + 1));
    }
    assert_same_branch(&full, &compact);

    // The recovered U solves the equations of motion exactly, the continuation's to the
    // corrector's tolerance on |F|, here its round-off floor eps max K_ii sqrt(n) max|u|
    // (4000 x 286 x eps = 2.5e-10 per unit displacement): the states differ by A(w)^{-1}
    // times that residual. Measured 1.1e-8 of the largest coefficient; the bound leaves a
    // factor 9 and is seven decades below the order-one difference of a wrong recovery.
    let difference = recovered_state_difference(&rod, &settings, &full, &compact);
    println!("recovered states: largest relative difference {difference:e}");
    assert!(difference <= 1e-7, "{difference:e}");

    // What is read from the recovered states: the contact reports, to the same bound.
    for (a, b) in full.points.iter().zip(&compact.points) {
        for (ca, cb) in a.contacts.iter().zip(&b.contacts) {
            let scale = ca.force_mean.abs().max(ca.displacement_max.abs());
            assert!((ca.force_mean - cb.force_mean).abs() <= 1e-7 * scale);
            assert!((ca.displacement_max - cb.displacement_max).abs() <= 1e-7 * scale);
            // The closed fraction of the period, from interpolated switching instants.
            assert!((ca.contact_fraction - cb.contact_fraction).abs() <= 1e-7);
        }
    }
}

#[test]
fn a_contact_force_sweep_decides_the_same_stability_as_the_full_sweep() {
    // The canonical modified-mass rod (20 elements, within the monodromy's dof limit) forced
    // with p0 = 0.2: an overhang whose middle branch is unstable.
    let rod = build_rod(&RodSpec {
        amplitude: 0.2,
        ..canonical(MassModel::Modified)
    })
    .unwrap();
    let settings = sweep_solver(Method::SsnHb, 20);
    let full = sweep(&rod, &settings, (0.8, 1.6), StateStorage::Full);
    let compact = sweep(&rod, &settings, (0.8, 1.6), StateStorage::ContactForces);
    assert_eq!(compact.state_storage, StateStorage::ContactForces);
    assert_same_branch(&full, &compact);
    let decided = full.stable().iter().filter(|s| s.is_some()).count();
    assert!(decided > full.points.len() / 2, "{decided} decided");
    assert!(full.stable().contains(&Some(false)), "the middle branch");
    assert_eq!(full.stable(), compact.stable());
    assert_eq!(full.events.len(), compact.events.len());
    for (a, b) in full.points.iter().zip(&compact.points) {
        // The multipliers are read from the contact's closed intervals of the recovered
        // state, whose switching instants move with the state (by 1e-8 relative at most on
        // the 2,000-element rod, less on this one's coarser round-off floor).
        match (a.stability.floquet_max_abs, b.stability.floquet_max_abs) {
            (Some(x), Some(y)) => assert!((x - y).abs() <= 1e-6 * x.max(1.0), "{x} vs {y}"),
            (x, y) => assert_eq!(x, y),
        }
    }
    let (pa, pb) = (full.located_peak.unwrap(), compact.located_peak.unwrap());
    assert!((pa.omega - pb.omega).abs() <= 1e-9 * pa.omega);
}

#[test]
fn a_contact_force_sweep_switches_to_the_same_period_two_branches() {
    // The two-dof chain with a stop on its free mass: a period doubling on its branch
    // (`chain_period_two.rs`), whose period-2 branch starts from the doubling point's full
    // state, recovered here from its contact forces.
    let structure = chain::chain(0.5, 0.02, [0.0, 0.1]);
    let settings = SolverSettings::with_harmonics(20);
    let mut range = SweepSettings::new(0.5, 3.0);
    range.period_two = true;
    let run =
        |storage| frequency_response_storing(&structure, &settings, &range, storage, None).unwrap();
    let (full, compact) = (run(StateStorage::Full), run(StateStorage::ContactForces));
    assert_eq!(compact.state_storage, StateStorage::ContactForces);
    assert_same_branch(&full, &compact);
    let followed = |o: &PeriodTwoOutcome| match o {
        PeriodTwoOutcome::Followed(b) => b.response.points.len(),
        _ => 0,
    };
    assert!(full.period_two.iter().any(|o| followed(o) > 100));
    assert_eq!(full.period_two.len(), compact.period_two.len());
    for (a, b) in full.period_two.iter().zip(&compact.period_two) {
        let (a, b) = match (a, b) {
            (PeriodTwoOutcome::Followed(a), PeriodTwoOutcome::Followed(b)) => (a, b),
            (
                PeriodTwoOutcome::NotStarted { from: x, .. },
                PeriodTwoOutcome::NotStarted { from: y, .. },
            ) => {
                assert_eq!((x.kind, x.index), (y.kind, y.index));
                continue;
            }
            _ => panic!("the same outcome: {a:?} / {b:?}"),
        };
        // The start is the doubling point's state perturbed along the flip's kernel: the
        // recovered state moves it by the corrector's residual (1e-8 relative at most,
        // above), which the period-2 solve at the start frequency absorbs to its tolerance.
        let relative = (a.start_omega - b.start_omega).abs() / a.start_omega;
        assert!(relative <= 1e-6, "{relative:e}");
        // The period-2 branch winds round a loop between 0.48 and 0.58 omega_1 several
        // times, and the turns amplify any difference: measured, the two branches agree to
        // 1e-13 over the first 90 points (the first turn and a half), to 4e-11 at point 150,
        // and part at the third turn (one leaves the loop after 354 points, the other is
        // still on it at the 2000-point limit). The first 100 points (or all), to 1e-9.
        let first = (a.response.points.len())
            .min(b.response.points.len())
            .min(100);
        for (p, q) in a.response.points.iter().zip(&b.response.points).take(first) {
            assert!((p.omega - q.omega).abs() <= 1e-9 * p.omega);
            assert!((p.amplitude - q.amplitude).abs() <= 1e-9 * p.amplitude);
            assert_eq!(p.stability.stable, q.stability.stable);
        }
    }
}
