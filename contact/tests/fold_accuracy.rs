//! Fold frequencies to an accuracy target: each fold of a coarse sweep located again with
//! more harmonics only around it, checked against whole sweeps at fixed harmonics on the
//! strongly forced rod (modified mass, `p0 = 0.2`, gap 0.5).

use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::fold_accuracy::{
    refine_folds, FoldAccuracy, FoldStop, MAX_FOLD_HARMONICS, SEGMENT_MAX_STEP,
};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

fn strong_rod() -> RodModel {
    build_rod(&RodSpec {
        mass: MassModel::Modified,
        amplitude: 0.2,
        ..RodSpec::canonical()
    })
    .expect("the strongly forced rod builds")
}

/// Both folds of the resonance, without the linear tails.
fn range() -> SweepSettings {
    SweepSettings {
        stability: false,
        ..SweepSettings::new(0.9, 1.3)
    }
}

fn sweep(rod: &RodModel, harmonics: usize) -> FrequencyResponse {
    sweep_with(rod, harmonics, &range())
}

fn sweep_with(rod: &RodModel, harmonics: usize, range: &SweepSettings) -> FrequencyResponse {
    let r =
        frequency_response(rod, &SolverSettings::with_harmonics(harmonics), range, None).unwrap();
    assert!(r.converged(), "H = {harmonics}: {}", r.termination);
    assert_eq!(r.folds.len(), 2, "H = {harmonics}: {:?}", r.folds);
    r
}

/// The folds of a sweep at `harmonics` refined to `target`.
fn refined(rod: &RodModel, harmonics: usize, target: (f64, usize)) -> Vec<FoldAccuracy> {
    let coarse = sweep(rod, harmonics);
    let settings = SolverSettings::with_harmonics(harmonics);
    refine_folds(rod, &settings, &range(), &coarse, target).unwrap()
}

/// The distance from `omega` to the nearest fold of `response` (infinite without folds).
fn distance_to_folds(response: &FrequencyResponse, omega: f64) -> f64 {
    response
        .folds
        .iter()
        .map(|w| (w - omega).abs())
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn folds_refined_around_themselves_equal_the_folds_of_a_whole_sweep_at_those_harmonics() {
    let rod = strong_rod();
    let folds = refined(&rod, 10, (1e-3, MAX_FOLD_HARMONICS));
    assert_eq!(folds.len(), 2);
    for fold in &folds {
        assert!(fold.met(), "{fold:?}");
        assert!(fold.rungs.len() >= 3, "{fold:?}");
        // The same branch at the same harmonics, with the segment's steps: the folds differ
        // by their interpolation between points on a piecewise-smooth branch (measured
        // 7e-7 and 2e-7 relative).
        let fine_steps = SweepSettings {
            max_step: SEGMENT_MAX_STEP,
            step: SEGMENT_MAX_STEP,
            ..range()
        };
        let whole = sweep_with(&rod, fold.harmonics(), &fine_steps);
        let nearest = distance_to_folds(&whole, fold.omega);
        assert!(
            nearest <= 5e-6 * fold.omega,
            "H = {}: segment {} against whole sweep {:?}",
            fold.harmonics(),
            fold.omega,
            whole.folds
        );
    }
}

#[test]
fn the_uncertainty_of_a_refined_fold_bounds_its_distance_to_the_folds_at_eight_times_the_harmonics()
{
    let rod = strong_rod();
    let folds = refined(&rod, 20, (1e-3, MAX_FOLD_HARMONICS));
    // The folds at H = 160 (measured 2.0e-5 relative from those at H = 320) stand for the
    // converged ones; each refined fold is within its uncertainty of them.
    let fine = sweep(&rod, 160);
    for fold in &folds {
        assert!(fold.met(), "{fold:?}");
        let uncertainty = fold.uncertainty.unwrap();
        assert!(uncertainty <= 1e-3 * fold.omega);
        let distance = distance_to_folds(&fine, fold.omega);
        assert!(
            distance <= uncertainty,
            "fold {} +- {uncertainty:e} at H = {}, H = 160 folds {:?}",
            fold.omega,
            fold.harmonics(),
            fine.folds
        );
    }
}

#[test]
fn a_ladder_that_cannot_reach_its_target_stops_at_the_harmonics_limit_and_says_so() {
    let rod = strong_rod();
    let folds = refined(&rod, 10, (1e-12, 40));
    assert_eq!(folds.len(), 2);
    for fold in &folds {
        assert!(!fold.met());
        assert_eq!(fold.stop, FoldStop::Limit { harmonics: 80 });
        let harmonics: Vec<usize> = fold.rungs.iter().map(|r| r.harmonics).collect();
        assert_eq!(harmonics, [10, 20, 40]);
        assert!(fold.uncertainty.unwrap() > 1e-12 * fold.omega);
    }
}
