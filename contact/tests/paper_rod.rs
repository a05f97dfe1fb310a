//! The paper's rod: SSN-HB from zero against closed forms and the time-marching reference.

mod common;

use common::{relative, solve_converged};

use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodSpec};
use semismooth_contact::settings::SolverSettings;
use semismooth_contact::solve::{solve, Solution};

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn march(spec: &RodSpec, steps: usize) -> Solution {
    let rod = build_rod(spec).unwrap();
    let settings = SolverSettings {
        max_periods: 5000,
        ..common::march(steps, 1e-10)
    };
    solve(&rod, rod.omega(), &settings, None).unwrap()
}

/// Exact steady response of the tip, `Re(U e^{i w t})` with `(K - w^2 M + i w D) U = f`,
/// solved densely in complex arithmetic (independent of the HB code).
fn exact_linear_tip(spec: &RodSpec, times: &[f64]) -> Vec<f64> {
    use nalgebra::Complex;
    let rod = build_rod(spec).unwrap();
    let (model, w) = (&rod.model, rod.omega());
    let tip = common::exact_linear(model, w)[model.dofs() - 1];
    times
        .iter()
        .map(|t| (tip * Complex::new((w * t).cos(), (w * t).sin())).re)
        .collect()
}

#[test]
fn without_contact_the_hb_answer_is_the_exact_linear_response_after_one_newton_step() {
    for (contacts, label) in [
        (vec![], "no contact"),
        (
            vec![RodContact {
                node: 20,
                gap: 10.0,
            }],
            "gap never reached",
        ),
    ] {
        let spec = RodSpec {
            contacts,
            frequency: semismooth_contact::rod::FrequencySpec::Ratio(0.9),
            ..RodSpec::canonical()
        };
        let rod = build_rod(&spec).unwrap();
        let s = solve(&rod, rod.omega(), &SolverSettings::with_harmonics(20), None).unwrap();
        assert!(s.converged(), "{label}");
        assert_eq!(s.iterations, 1, "{label}: Newton must stop after one step");
        let exact = exact_linear_tip(&spec, &s.times);
        let scale = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let error = s
            .observed
            .iter()
            .zip(&exact)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        // Both are direct solves of the same linear algebra: round-off only.
        assert!(
            error <= 1e-12 * scale,
            "{label}: error {error:e} vs scale {scale}"
        );
    }
}

#[test]
fn canonical_case_converges_from_zero_for_every_harmonic_count_from_5_to_40() {
    for mass in [MassModel::Consistent, MassModel::Modified] {
        let rod = build_rod(&common::canonical(mass)).unwrap();
        for h in [5, 10, 15, 20, 25, 30, 35, 40] {
            let s = solve(&rod, rod.omega(), &SolverSettings::with_harmonics(h), None).unwrap();
            assert!(
                s.converged() && s.residual_norm <= 1e-10,
                "{mass:?} H = {h}: {} after {} iterations, residual {:e}",
                s.termination,
                s.iterations,
                s.residual_norm
            );
            // Physically plausible: the contact pushes (mean force <= 0) and the obstacle
            // is respected up to the resolution of H harmonics: the penetration between
            // the AFT samples shrinks like 1/H (measured H x penetration / gap from 0.063
            // to 0.124 over both masses and H = 5..40), asserted below 0.2 gap / H.
            assert!(s.stats.mean_contact_force < 0.0);
            println!(
                "{mass:?} H = {h}: {} iterations, tip min {:.6}, penetration {:.2e}",
                s.iterations, s.stats.min, s.stats.max_penetration
            );
            let bound = 0.2 * 0.5 / h as f64;
            assert!(
                s.stats.max_penetration < bound,
                "{mass:?} H = {h}: penetration {:e} above {bound:e}",
                s.stats.max_penetration
            );
        }
    }
}

#[test]
fn modified_mass_hb_converges_to_the_time_marching_reference() {
    // Reference: the energy-conserving trapezoidal scheme, refined until the step's effect
    // is below the tolerances checked here (observed order printed and checked).
    let spec = common::canonical(MassModel::Modified);
    let coarse = march(&spec, 1000);
    let medium = march(&spec, 2000);
    let fine = march(&spec, 4000);
    // The tip minimum is already converged to ~1e-7 at 2000 steps (its sampling error is
    // below that): measure the order on the mean contact force, a smooth functional.
    let f = [&coarse, &medium, &fine].map(|s| s.stats.mean_contact_force);
    let order = ((f[0] - f[1]) / (f[1] - f[2])).abs().log2();
    let d_min = relative(medium.stats.min, fine.stats.min);
    println!(
        "march mean force: {:.10} {:.10} {:.10}, observed order {order:.2}; tip min change {d_min:.1e}",
        f[0], f[1], f[2]
    );
    assert!(
        order > 1.5,
        "time marching must converge with the step (order {order})"
    );
    assert!(
        d_min < 1e-5,
        "reference not converged: last change {d_min:e}"
    );

    let rod = build_rod(&spec).unwrap();
    let mut errors = Vec::new();
    for h in [10, 20, 40] {
        let s = solve_converged(&rod, &SolverSettings::with_harmonics(h));
        let e_min = relative(s.stats.min, fine.stats.min);
        let e_rms = relative(rms(&s.observed), rms(&fine.observed));
        let e_force = relative(s.stats.mean_contact_force, fine.stats.mean_contact_force);
        // The fraction of the period in contact: SSN-HB's is the measure of its contact
        // law's active set, the march's that of its compressive samples.
        let fraction = s.contacts[0].contact_fraction;
        let exact = fine.contacts[0].contact_fraction;
        println!(
            "H = {h}: {} iterations, tip min {:.8} (rel. error {e_min:.2e}), rms error {e_rms:.2e}, mean force error {e_force:.2e}, contact fraction {fraction:.4} (march {exact:.4})",
            s.iterations, s.stats.min
        );
        // The truncated series resolves nothing shorter than half the period of its
        // highest harmonic, T / (2H): the ends of the closed interval are known to that
        // (measured: 0.0718, 0.0647, 0.0673 against 0.0620 at H = 10, 20, 40), where the
        // force reconstructed from the series (which rings and is partly tensile) would
        // give about 0.5.
        assert!(
            (fraction - exact).abs() <= 1.0 / (2 * h) as f64,
            "H = {h}: contact fraction {fraction} against {exact}"
        );
        errors.push(e_min);
        if h == 40 {
            // Within 1e-3 in the minimum and the RMS, 1e-2 in the mean force.
            assert!(e_min < 1e-3 && e_rms < 1e-3 && e_force < 1e-2);
        }
    }
    assert!(
        errors[2] < errors[0],
        "HB error must shrink from H = 10 to H = 40: {errors:?}"
    );
}

#[test]
fn dependence_of_the_answer_on_c_shrinks_as_harmonics_grow() {
    // The Galerkin projection of max(0, c(Gu - g) - lambda) is not invariant to c: at finite H
    // the answer depends on it, and the dependence is a truncation effect that must vanish as
    // H grows. c over two decades around the default (0.3 to 30 x the static stiffness).
    let rod = build_rod(&common::canonical(MassModel::Modified)).unwrap();
    let k_static = rod.model.static_contact_stiffness().unwrap();
    assert!(
        (k_static - 1.0).abs() < 1e-12,
        "EA/L = 1 for the canonical rod"
    );
    let mut spreads = Vec::new();
    for h in [10, 20, 40] {
        let minima: Vec<f64> = [0.3, 1.0, 3.0, 10.0, 30.0]
            .iter()
            .map(|&factor| {
                let settings = SolverSettings {
                    c: Some(factor * k_static),
                    ..SolverSettings::with_harmonics(h)
                };
                let s = solve_converged(&rod, &settings);
                assert_eq!(s.c, Some(factor * k_static), "the JSON reports the c used");
                s.stats.min
            })
            .collect();
        let spread = minima.iter().cloned().fold(f64::MIN, f64::max)
            - minima.iter().cloned().fold(f64::MAX, f64::min);
        println!("H = {h}: tip minima over c = {minima:?}, spread {spread:.2e}");
        spreads.push(spread / 0.523);
    }
    assert!(
        spreads[2] < spreads[1] && spreads[1] < spreads[0],
        "relative spreads {spreads:?}"
    );
}
