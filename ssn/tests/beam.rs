//! The second shipped structure, independent of the rod: the Euler–Bernoulli cantilever of
//! `examples/beam_matrices.rs`, read from its committed Matrix Market files through
//! `scenes/beam_tip_stop.toml`. Checked against the analytic natural frequencies,
//! against time marching with contact, and through a sweep over its first resonance.

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::solve::Solution;
use semismooth_contact::sweep::frequency_response;
use ssn::scene::{Method, Scene, SolverSettings};

mod common;

fn beam() -> (Scene, Structure) {
    let scene = Scene::from_path(common::scenes_dir().join("beam_tip_stop.toml")).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    (scene, structure)
}

/// `beta_k L` of the clamped-free beam, roots of `cos(b) cosh(b) = -1` (to 1e-12 by
/// bisection here, not from a table).
fn beta(k: usize) -> f64 {
    let g = |b: f64| b.cos() * b.cosh() + 1.0;
    // The k-th root lies within 0.5 of (2k - 1) pi / 2 (cosh is large there and g has the
    // sign of cos); the first in (1, 3).
    let centre = (2 * k - 1) as f64 * std::f64::consts::FRAC_PI_2;
    let (mut lo, mut hi) = if k == 1 {
        (1.0, 3.0)
    } else {
        (centre - 0.5, centre + 0.5)
    };
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn natural_frequencies_are_the_analytic_ones_within_the_discretisation_error() {
    let (_, s) = beam();
    let freqs = natural_frequencies(&s.model, 4).unwrap();
    assert!((beta(1) - 1.875104).abs() < 1e-6 && (beta(2) - 4.694091).abs() < 1e-6);
    // Hermite cubics with a consistent mass overestimate the frequencies by a relative
    // (beta_k h)^4 / 1440 at leading order: with h = 1/20 the measured error / (beta_k h)^4
    // is 6.94e-4 / 6.91e-4 / 6.88e-4 / 6.84e-4 for modes 1..4 (1/1440 = 6.94e-4), from
    // 5.4e-8 (mode 1) to 6.2e-5 (mode 4). Bound: (beta_k h)^4 / 1400.
    let h = 1.0 / 20.0;
    for (k, w) in freqs.iter().enumerate() {
        let b = beta(k + 1);
        let exact = b * b;
        let error = (w - exact).abs() / exact;
        let bound = (b * h).powi(4) / 1400.0;
        assert!(
            error <= bound && *w >= exact,
            "mode {}: {w} against {exact}: relative error {error:e} > {bound:e} (or below the exact value)",
            k + 1
        );
    }
    assert_eq!(s.observed_dof, 38, "the tip deflection");
    assert!((s.omega_1 - freqs[0]).abs() < 1e-14 * freqs[0]);
}

/// `s` solved at `scene`'s frequency with its settings changed by `edit`.
fn solve(s: &Structure, scene: &Scene, edit: impl Fn(&mut SolverSettings)) -> Solution {
    let mut settings = scene.solver.clone();
    edit(&mut settings);
    let omega = scene.omega(s.omega_1);
    let sol = semismooth_contact::solve(s, omega, &settings, None).unwrap();
    assert!(
        sol.converged(),
        "{:?}: {}",
        settings.method,
        sol.termination
    );
    sol
}

#[test]
fn ssn_hb_agrees_with_time_marching_within_the_truncation_error() {
    let (scene, s) = beam();
    let march = solve(&s, &scene, |v| {
        v.method = Method::March;
        v.steps_per_period = 2000;
    });
    let gap = s.model.contacts[0].gap;
    assert!(march.stats.max > gap, "the tip must reach the stop");
    let mut errors = Vec::new();
    for h in [10, 20, 40] {
        let hb = solve(&s, &scene, |v| {
            v.harmonics = h;
            v.time_samples = ssn::scene::default_hb_time_samples(h);
        });
        let tip = common::relative(hb.stats.min, march.stats.min);
        let force = common::relative(hb.stats.mean_contact_force, march.stats.mean_contact_force);
        eprintln!("H = {h}: tip min {:.6e} (march {:.6e}, rel {tip:.2e}), mean force {:.6e} (march {:.6e}, rel {force:.2e})",
            hb.stats.min, march.stats.min, hb.stats.mean_contact_force, march.stats.mean_contact_force);
        errors.push((tip, force));
    }
    // Measured (march 2000 steps per period): tip minimum 3e-4 / 1.2e-4 / 4e-5 and mean
    // contact force 1.9e-2 / 4.2e-3 / 1.4e-3 at H = 10 / 20 / 40: the truncation error falls
    // with H. Bounds at twice these.
    let bounds = [(6e-4, 4e-2), (2.4e-4, 8.4e-3), (8e-5, 2.8e-3)];
    for ((tip, force), (bt, bf)) in errors.iter().zip(bounds) {
        assert!(*tip <= bt && *force <= bf, "{errors:?}");
    }
    assert!(errors[2].1 < errors[0].1, "{errors:?}");
}

#[test]
fn a_sweep_through_the_first_resonance_folds_at_the_stop_and_is_linear_off_contact() {
    let (scene, s) = beam();
    let mut settings = scene.solver.clone();
    settings.harmonics = 10;
    settings.time_samples = ssn::scene::default_hb_time_samples(10);
    let sweep = scene.sweep.clone().unwrap();
    let r = frequency_response(&s, &settings, &sweep, None).unwrap();
    assert!(r.converged(), "{}", r.termination);
    let gap = s.model.contacts[0].gap;
    let ratio = r.omega_ratio();
    eprintln!(
        "{} points, folds {:?}, peak {:?}",
        r.points.len(),
        r.folds.iter().map(|w| w / s.omega_1).collect::<Vec<_>>(),
        r.peak().map(|(i, a)| (ratio[i], a))
    );
    // Off contact (both ends), the branch is the linear response, exactly.
    for i in [0, r.points.len() - 1] {
        let w = r.points[i].omega;
        let z = common::exact_linear(&s.model, w)[s.observed_dof];
        assert!(r.points[i].observed_max < gap);
        assert!(
            common::relative(r.points[i].amplitude, z.norm()) < 1e-4,
            "omega/omega_1 = {}: {} vs {}",
            ratio[i],
            r.points[i].amplitude,
            z.norm()
        );
    }
    // The stop bounds the tip, stiffens the beam (peak above omega_1) and folds the branch.
    let (peak, _) = r.peak().unwrap();
    assert!(ratio[peak] > 1.0, "{}", ratio[peak]);
    let highest = r
        .column(|p| p.observed_max)
        .iter()
        .cloned()
        .fold(f64::MIN, f64::max);
    // SSN-HB enforces the contact on the Fourier projection: the reconstructed tip passes
    // the stop by up to 5 % of the gap at H = 10 (measured 1.050).
    assert!(highest < 1.06 * gap && highest > gap, "{highest}");
    assert!(r.folds.len() >= 2, "{:?}", r.folds);
}
