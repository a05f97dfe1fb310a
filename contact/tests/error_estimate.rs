//! The error estimate of every method (`Solution::error_estimate`) against the true error,
//! and the discretisation search (`SolverSettings::accuracy`) meeting its target.
//!
//! The true error is the relative error of the reported quantities (the tip's extremes, the
//! mean contact force; `RelativeErrors::between`) against time marching at 8000 trapezoidal
//! steps per period on the canonical rod with the massless contact node (its own error,
//! Richardson from 4000 steps, is 3e-6 on the paper's rod and 4e-7 on the strongly forced
//! one: below a tenth of every error compared here, so the true errors are known to 10 %).
//! The estimate must lie within `[true / 3, 10 true]`: the bounds the estimate promises.

mod common;

use common::solve_converged as solve;

use semismooth_contact::accuracy::{RelativeErrors, ReportedQuantities, SearchStop};
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};
use semismooth_contact::settings::{Method, SolverSettings};
use semismooth_contact::solve::Solution;

/// The paper's rod with the massless contact node, forced with `amplitude`.
fn rod(amplitude: f64) -> RodModel {
    build_rod(&RodSpec {
        amplitude,
        ..common::canonical(MassModel::Modified)
    })
    .unwrap()
}

/// The reported quantities of the time-marching reference (8000 steps per period).
fn reference(rod: &RodModel) -> ReportedQuantities {
    let settings = SolverSettings {
        estimate_error: false,
        ..common::march(8000, 1e-10)
    };
    ReportedQuantities::of(&solve(rod, &settings))
}

fn true_error(s: &Solution, reference: &ReportedQuantities) -> f64 {
    RelativeErrors::between(&ReportedQuantities::of(s), reference).largest()
}

/// `(label, settings)` of each method at a setting of the method comparison's range.
fn settings() -> Vec<(&'static str, SolverSettings)> {
    let with = |method: Method, f: &dyn Fn(&mut SolverSettings)| {
        let mut s = SolverSettings::for_method(method);
        f(&mut s);
        s
    };
    vec![
        ("ssn-hb H=20", with(Method::SsnHb, &|s| s.harmonics = 20)),
        (
            "penalty-hb H=40",
            with(Method::PenaltyHb, &|s| {
                s.harmonics = 40;
                s.time_samples = semismooth_contact::settings::default_hb_time_samples(40);
            }),
        ),
        (
            "lcp-lemke Nt=256",
            with(Method::LcpLemke, &|s| s.time_samples = 256),
        ),
        (
            "lcp-ssn Nt=512",
            with(Method::LcpSsn, &|s| s.time_samples = 512),
        ),
        (
            "march 1000 steps",
            with(Method::March, &|s| s.steps_per_period = 1000),
        ),
    ]
}

#[test]
fn every_methods_estimate_is_within_a_third_and_ten_times_the_true_error() {
    for amplitude in [0.04, 0.2] {
        let rod = rod(amplitude);
        let reference = reference(&rod);
        for (label, settings) in settings() {
            let s = solve(&rod, &settings);
            let truth = true_error(&s, &reference);
            let estimate = s
                .error_estimate
                .as_ref()
                .unwrap_or_else(|why| panic!("p0 = {amplitude}, {label}: no estimate: {why:?}"))
                .relative;
            let ratio = estimate / truth;
            assert!(
                (1.0 / 3.0..=10.0).contains(&ratio),
                "p0 = {amplitude}, {label}: estimate {estimate:.2e}, true error {truth:.2e}"
            );
        }
    }
}

#[test]
fn the_search_meets_its_target_against_the_reference_with_an_estimate_within_bounds() {
    let rod = rod(0.2);
    let reference = reference(&rod);
    for method in [Method::SsnHb, Method::LcpSsn, Method::March] {
        let settings = SolverSettings {
            accuracy: Some(1e-3),
            ..SolverSettings::for_method(method)
        };
        let s = solve(&rod, &settings);
        let search = s.search.as_ref().expect("a search record");
        assert_eq!(search.stop, SearchStop::Met, "{method:?}");
        let truth = true_error(&s, &reference);
        let estimate = s.error_estimate.as_ref().unwrap().relative;
        assert!(estimate <= 1e-3, "{method:?}: estimate {estimate:.2e}");
        assert!(truth <= 1e-3, "{method:?}: true error {truth:.2e}");
        assert!(
            (truth / 3.0..=10.0 * truth).contains(&estimate),
            "{method:?}: estimate {estimate:.2e}, true error {truth:.2e}"
        );
        // The search's cost is its solves': every step's work is in its counters.
        let steps: u64 = search
            .steps
            .iter()
            .map(|s| s.counters.residual_evaluations)
            .sum();
        assert_eq!(steps, search.counters.residual_evaluations, "{method:?}");
    }
}

#[test]
fn an_estimate_is_refused_with_a_reason_on_the_coarsest_discretisation() {
    let rod = rod(0.04);
    let settings = SolverSettings {
        method: Method::LcpSsn,
        time_samples: semismooth_contact::lcp::MIN_LCP_TIME_SAMPLES,
        ..SolverSettings::default()
    };
    let s = solve(&rod, &settings);
    assert!(
        matches!(
            s.error_estimate,
            Err(semismooth_contact::accuracy::NoEstimate::Coarsest { .. })
        ),
        "{:?}",
        s.error_estimate
    );
}
