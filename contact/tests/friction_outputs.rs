//! The friction points of a solution (tangential force, slip velocity, stick fraction,
//! force amplitude) on Den Hartog's single-dof oscillator, and the regularised (tanh)
//! friction of penalty HB against the exact SSN-HB as the regularisation narrows.

use semismooth_contact::model::Structure;
mod common;

use semismooth_contact::model::{ContactRow, FrictionPoint, SparseMatrix, StructuralModel};
use semismooth_contact::settings::{Method, SolverSettings};
use semismooth_contact::solve::Solution;

/// `x'' + c x' + x = cos(w t) + lambda_t` with Coulomb friction `|lambda_t| <= mu N`,
/// `mu = 0.5`, `N = 2 slip_limit`.
fn oscillator(c: f64, slip_limit: f64) -> Structure {
    let one = |v: f64| {
        SparseMatrix::try_new_from_triplets(1, 1, &[faer::sparse::Triplet::new(0, 0, v)]).unwrap()
    };
    let model = StructuralModel::new(one(1.0), one(1.0), vec![1.0])
        .with_damping(one(c))
        .with_friction(FrictionPoint::prescribed(
            ContactRow::unit(0, 1.0),
            0.5,
            2.0 * slip_limit,
        ));
    Structure::new(model, 0).unwrap()
}

/// The solve of `method` with `harmonics` at `w` (asserted converged).
fn solve(structure: &Structure, w: f64, settings: SolverSettings) -> Solution {
    let settings = SolverSettings {
        estimate_error: false,
        ..settings
    };
    let s = semismooth_contact::solve(structure, w, &settings, None).unwrap();
    assert!(s.converged(), "{:?}: {}", settings.method, s.termination);
    s
}

fn hb(method: Method, harmonics: usize) -> SolverSettings {
    SolverSettings {
        method,
        harmonics,
        time_samples: semismooth_contact::settings::default_hb_time_samples(harmonics),
        ..SolverSettings::default()
    }
}

#[test]
fn den_hartogs_oscillator_slips_at_the_slip_limit_or_sticks_all_period() {
    // Gross slip (slip limit 0.3 F0 at w = 0.7, zeta = 0.01: Den Hartog's continuous
    // sliding): the law's force is mu N wherever the point slips, so its amplitude is mu N
    // to round-off. It sticks only where its velocity reverses: two instants of the exact
    // solution, and in harmonic balance two bands where the law's argument
    // `lambda_t - c y_t` crosses the interval `[-b, b]`, each about `2 b / (c |y'|)` wide
    // (measured 0.78 % of the period at H = 20 and 40: c = 10, not H, sets it).
    let slipping = oscillator(0.02, 0.3);
    let mut fractions = Vec::new();
    for h in [20, 40] {
        for method in [Method::SsnHb, Method::March] {
            let settings = match method {
                Method::SsnHb => hb(method, h),
                _ => SolverSettings {
                    method,
                    steps_per_period: 2000,
                    ..SolverSettings::default()
                },
            };
            let s = solve(&slipping, 0.7, settings);
            let f = &s.friction[0];
            assert_eq!(s.friction.len(), 1);
            assert_eq!(f.force.len(), s.times.len());
            assert_eq!(f.slip_velocity.len(), s.times.len());
            assert!(
                (f.summary.force_amplitude - 0.3).abs() < 1e-12,
                "{method:?}: {}",
                f.summary.force_amplitude
            );
            assert_eq!(f.summary.slip_limit_max, 0.3);
            // The march's steps stick at no step (continuous sliding).
            if method == Method::March {
                assert_eq!(f.summary.stick_fraction, 0.0);
                continue;
            }
            fractions.push(f.summary.stick_fraction);
            // The force opposes the slip wherever the point slips fast.
            let fast = 0.1 * f.summary.slip_velocity_amplitude;
            for (l, v) in f.force.iter().zip(&f.slip_velocity) {
                if v.abs() > fast {
                    assert!((l + 0.3 * v.signum()).abs() < 1e-12, "{l} at {v}");
                }
            }
        }
    }
    eprintln!("gross slip: stick fractions at H = 20, 40: {fractions:?}");
    assert!(fractions.iter().all(|s| *s < 1e-2), "{fractions:?}");

    // Full stick: a slip limit far above the force the point carries (the whole load,
    // |F0| = 1, and no motion: x = 0): it sticks all period and carries -cos(w t).
    let stuck = oscillator(0.02, 20.0);
    for method in [Method::SsnHb, Method::March] {
        let settings = match method {
            Method::SsnHb => hb(method, 10),
            _ => SolverSettings {
                method,
                steps_per_period: 500,
                ..SolverSettings::default()
            },
        };
        let s = solve(&stuck, 0.7, settings);
        let f = &s.friction[0].summary;
        assert_eq!(f.stick_fraction, 1.0, "{method:?}");
        // The force balances the load: amplitude 1 (Newton's tolerance 1e-10 on a unit
        // system; a march step's impulse averages the load over the step, which takes
        // `(w h)^2 / 2` = 8e-5 off the cosine's peak at 500 steps: measured 3.9e-5).
        let tolerance = if method == Method::March { 1e-4 } else { 1e-8 };
        assert!(
            (f.force_amplitude - 1.0).abs() < tolerance,
            "{method:?}: {f:?}"
        );
    }
}

#[test]
fn regularised_friction_approaches_the_exact_law_as_its_width_shrinks() {
    // Both formulations at the same H and Nt, so that only the law differs. Stick-slip
    // (slip limit 0.7 F0 at w = 0.6, zeta = 0.05, H = 80: the mass sticks for part of each
    // half period) and gross slip (Den Hartog's case, H = 40). tanh(v / eps) creeps where
    // Coulomb sticks: the error falls like eps (measured 9.99e-2, 1.13e-2, 7.1e-4 at widths
    // 1e-1, 1e-2, 1e-3 in stick-slip: 0.95 and 1.2 decades per decade) down to the gap
    // between the two laws' H-harmonic solutions (3.7e-4 at 1e-4 in stick-slip, 1.08e-3 in
    // gross slip, where SSN-HB's reversal bands count as stick): below the truncation
    // error of either at that H (SSN-HB against the exact march: 0.24 % at H = 80 in
    // stick-slip; against Den Hartog 0.14 % at H = 40, contact/tests/friction.rs).
    let widths = [1e-1, 1e-2, 1e-3, 1e-4];
    for (name, structure, w, h) in [
        ("stick-slip", oscillator(0.1, 0.7), 0.6, 80),
        ("gross slip", oscillator(0.02, 0.3), 0.7, 40),
    ] {
        let exact = solve(&structure, w, hb(Method::SsnHb, h));
        let reference = common::first_harmonic(&exact.observed);
        let errors: Vec<f64> = widths
            .iter()
            .map(|&width| {
                let settings = SolverSettings {
                    friction_regularisation: width,
                    ..hb(Method::PenaltyHb, h)
                };
                let s = solve(&structure, w, settings);
                // The regularised force never exceeds mu N (tanh < 1).
                let f = &s.friction[0].summary;
                assert!(f.force_amplitude <= f.slip_limit_max, "{f:?}");
                (common::first_harmonic(&s.observed) - reference).abs() / reference
            })
            .collect();
        let rates: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log10()).collect();
        eprintln!(
            "{name}, H = {h}: regularised against exact SSN-HB (first harmonic {reference}): \
             relative errors at widths {widths:?}: {errors:?}, decades per decade: {rates:?}"
        );
        if name == "stick-slip" {
            assert!(exact.friction[0].summary.stick_fraction > 0.05);
            assert!(rates[0] > 0.8 && rates[1] > 0.8, "{rates:?}");
            assert!(errors[3] < 1e-3, "{errors:?}");
        } else {
            assert!(errors[1..].iter().all(|e| *e < 1.5e-3), "{errors:?}");
        }
    }
}
