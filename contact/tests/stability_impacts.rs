//! Floquet multipliers of harmonic-balance solutions whose contact dof carries mass (the
//! paper's consistent-mass rod) against Moreau–Jean time marching with restitution 0 (the
//! impact law the monodromy's saltations assume): started from the harmonic-balance orbit
//! plus a small perturbation, the march's period-to-period change decays or grows at the
//! rate of the largest multiplier.

#[path = "common/orbit_march.rs"]
mod orbit_march;

use orbit_march::{distance, moreau_jean, snapshot};
use semismooth_contact::march::TimeMarcher;
use semismooth_contact::rod::{build_rod, RodModel, RodSpec};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::stability::{hb_stability, hb_state};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

/// The canonical rod (consistent mass, tip gap `gap`) forced at `amplitude`, swept over
/// `[from, to] omega_1` with SSN-HB at `harmonics`.
fn rod_sweep(
    gap: f64,
    amplitude: f64,
    harmonics: usize,
    from: f64,
    to: f64,
) -> (RodModel, SolverSettings, FrequencyResponse) {
    let rod = build_rod(&RodSpec {
        amplitude,
        ..RodSpec::canonical().with_tip_gap(Some(gap))
    })
    .unwrap();
    let settings = SolverSettings::with_harmonics(harmonics);
    let sweep = SweepSettings {
        max_step: 0.01,
        ..SweepSettings::new(from, to)
    };
    let r = frequency_response(&rod, &settings, &sweep, None).unwrap();
    assert!(r.converged(), "{:?}", r.termination);
    (rod, settings, r)
}

/// A Moreau–Jean march (restitution 0, `steps_per_period` steps) of `rod` at `omega` from
/// the harmonic-balance orbit `x` plus `perturbation` on the displacements.
fn marcher_from_orbit<'a>(
    rod: &'a RodModel,
    harmonics: usize,
    omega: f64,
    x: &[f64],
    perturbation: f64,
    steps_per_period: usize,
) -> TimeMarcher<'a> {
    let n = rod.model.dofs();
    let mut start = hb_state(
        &rod.model,
        harmonics,
        omega,
        &x[..n * (2 * harmonics + 1)],
        0.0,
    )
    .unwrap();
    for (i, u) in start.displacement.iter_mut().enumerate() {
        *u += perturbation * ((i + 1) as f64 * 0.7).sin();
    }
    let options = moreau_jean(steps_per_period, 0.0);
    TimeMarcher::new(&rod.model, omega, &options, &start).unwrap()
}

/// The period-to-period changes `|x_{k+1} - x_k|` of `periods` more periods of `marcher`.
fn changes(marcher: &mut TimeMarcher, omega: f64, steps: usize, periods: usize) -> Vec<f64> {
    let mut previous = snapshot(marcher, omega);
    (0..periods)
        .map(|_| {
            for _ in 0..steps {
                marcher.step().unwrap();
            }
            let now = snapshot(marcher, omega);
            let d = distance(&now, &previous);
            previous = now;
            d
        })
        .collect()
}

/// Per-period factor of `changes[from..to]`: least-squares slope of `ln d_k` against `k`.
fn fitted_rate(changes: &[f64], from: usize, to: usize) -> f64 {
    let points: Vec<(f64, f64)> = (from..to).map(|k| (k as f64, changes[k].ln())).collect();
    let m = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / m, b + y / m));
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (sxy / sxx).exp()
}

/// Steps per period of the Moreau–Jean marches (first order at the impacts).
const STEPS: usize = 4000;

#[test]
fn largest_multiplier_predicts_the_decay_and_growth_of_moreau_jean_marching_on_a_mass_carrying_contact(
) {
    let h = 20;
    let (rod, settings, r) = rod_sweep(0.5, 0.04, h, 0.8, 1.6);
    let w1 = rod.omega_1;
    assert_eq!(r.fold_indices.len(), 2, "folds {:?}", r.folds);
    let (upper_fold, lower_fold) = (r.fold_indices[0], r.fold_indices[1]);
    // Stable points with contact on the upper branch: march to the Moreau–Jean orbit, then
    // perturb it by 1e-6 per dof and fit the decay over periods 2 to 20 (the dominant mode
    // by then, still above round-off).
    let options = moreau_jean(STEPS, 0.0);
    let mut checked = 0;
    for i in (upper_fold / 2..upper_fold).step_by(16) {
        let omega = r.points[i].omega;
        let s = hb_stability(&rod.model, &settings, omega, &r.points[i].state).unwrap();
        assert!(s.closings > 0, "point {i} at {}: no contact", omega / w1);
        assert_eq!(s.stable, Some(true), "point {i} at {}", omega / w1);
        let mu = s.floquet_max_abs.unwrap();
        let mut marcher = marcher_from_orbit(&rod, h, omega, &r.points[i].state, 0.0, STEPS);
        let settle = changes(&mut marcher, omega, STEPS, 200);
        let mut start = marcher.state();
        let settled = settle[199] < 1e-9;
        for (k, u) in start.displacement.iter_mut().enumerate() {
            *u += 1e-6 * ((k + 1) as f64 * 0.7).sin();
        }
        let mut perturbed = TimeMarcher::new(&rod.model, omega, &options, &start).unwrap();
        let decay = changes(&mut perturbed, omega, STEPS, 20);
        let rate = fitted_rate(&decay, 2, 20);
        println!(
            "{i} at {:.4}: |mu| {mu:.4} ({} phases), march settled to {:.1e}, decay rate {rate:.4}",
            omega / w1,
            s.phases,
            settle[199],
        );
        // Measured from 14 % below to 11 % above |mu| (every eighth point). A perturbation this small leaves each
        // impact in its step (the tip travels 8e-4 in a step), and Moreau–Jean's velocity
        // projection then keeps the contact dof's position perturbation through the closed
        // phase where the flow's impact removes it: its linearisation differs by a little.
        // Larger perturbations leave the linear regime before the dominant mode shows. A
        // march that keeps a chatter of the tip node above 1e-9 after 200 periods has no
        // orbit to perturb: not checked.
        if settled {
            assert!(
                (rate - mu).abs() <= 0.15 * mu,
                "point {i}: decay rate {rate} against the largest multiplier {mu}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 2, "only {checked} marches settled");
    // An unstable point in the middle of the branch between its folds: from the
    // harmonic-balance orbit plus 1e-8 the march leaves at the rate of the largest
    // multiplier (the orbits differ by about 1e-2, so the growth is fitted from the start;
    // measured 1.0265 against |mu| 1.0859).
    let i = (upper_fold + lower_fold) / 2;
    let omega = r.points[i].omega;
    let s = hb_stability(&rod.model, &settings, omega, &r.points[i].state).unwrap();
    assert_eq!(s.stable, Some(false), "point {i} at {}", omega / w1);
    let mu = s.floquet_max_abs.unwrap();
    let mut marcher = marcher_from_orbit(&rod, h, omega, &r.points[i].state, 1e-8, STEPS);
    let growth = changes(&mut marcher, omega, STEPS, 12);
    let rate = fitted_rate(&growth, 1, 12);
    println!(
        "{i} at {:.4}: |mu| {mu:.4}, growth rate {rate:.4}",
        omega / w1
    );
    assert!(
        rate > 1.0 && (rate - mu).abs() <= 0.1 * mu,
        "point {i}: growth rate {rate} against the largest multiplier {mu}: {growth:?}"
    );
}
