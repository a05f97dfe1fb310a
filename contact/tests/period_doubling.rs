//! The period-2 branch of a sweep: on the bilinear oscillator (a massless node behind a
//! spring against a stop at zero gap), the sweep's period doubling is where the periodic
//! orbit of the time-marching map has its multiplier through -1, and the switched branch's
//! stable points are 2T-periodic orbits that time marching from them stays on.

mod common;

use common::sparse;
use semismooth::floquet::BifurcationKind;
use semismooth_contact::march::{MarchOptions, MarchScheme, TimeMarcher};
use semismooth_contact::model::{ContactPoint, HarmonicLoad, StructuralModel, Structure};
use semismooth_contact::settings::{GlobalizationChoice, Method, SolverSettings, SweepSettings};
use semismooth_contact::stability::{hb_state, map_stability, StabilityOptions};
use semismooth_contact::sweep::doubling::{on_half_frequency, PeriodTwoOutcome};
use semismooth_contact::sweep::frequency_response;

/// `u'' + 2 zeta u' + u = -k_c (u - w) + cos(w t)`, the massless node `w` held by a stop at
/// 0: stiffness 1 while `u < 0`, `1 + k_c` beyond. With zero gap the system is positively
/// homogeneous, so whether the response doubles its period depends on `w` alone.
fn bilinear(k_c: f64, zeta: f64, gap: f64) -> Structure {
    let model = StructuralModel {
        mass: sparse(2, &[(0, 0, 1.0)]),
        damping: Some(sparse(2, &[(0, 0, 2.0 * zeta)])),
        stiffness: sparse(
            2,
            &[(0, 0, 1.0 + k_c), (0, 1, -k_c), (1, 0, -k_c), (1, 1, k_c)],
        ),
        load: HarmonicLoad::cosine(vec![1.0, 0.0]),
        contacts: vec![ContactPoint::new(1, gap)],
        friction: Vec::new(),
        cyclic: None,
        frictional_contacts: Vec::new(),
    };
    Structure {
        model,
        omega_1: 1.0,
        observed_dof: 0,
    }
}

/// `det(I + M) = prod (1 + mu)` over the multipliers of the time-stepping map's own
/// periodic orbit next to the harmonic-balance coefficients `u` (`h` harmonics) at `omega`:
/// it changes sign where a real multiplier passes `-1` (a complex pair adds `|1 + mu|^2`).
fn map_flip_determinant(model: &StructuralModel, h: usize, omega: f64, u: &[f64]) -> f64 {
    let u = &u[..model.dofs() * (2 * h + 1)];
    let s = map_stability(model, h, omega, u, &StabilityOptions::default()).unwrap();
    assert!(s.orbit.is_some(), "{s:?}");
    let (re, im) = s.multipliers.values().iter().fold((1.0, 0.0), |(a, b), z| {
        let (c, d) = (1.0 + z.0, z.1);
        (a * c - b * d, a * d + b * c)
    });
    assert!(im.abs() <= 1e-9 * re.abs().max(1e-300), "{re} {im}");
    re
}

/// The distances `|y(2T) - y(0)|` and `|y(T) - y(0)|` of the first two periods, and
/// `|y(2kT) - y(0)|` after `periods` (even) periods, marching `model` at `omega` from the
/// state `(u, v / omega)` of the period-2 harmonic-balance coefficients `u` (`h` harmonics
/// of `omega / 2`, `model_half` forced on harmonic 2).
fn march_from(
    model: &StructuralModel,
    model_half: &StructuralModel,
    h: usize,
    omega: f64,
    u: &[f64],
    periods: usize,
) -> (f64, f64, f64) {
    let steps = 4000;
    let options = MarchOptions {
        steps_per_period: steps,
        scheme: MarchScheme::MasslessContactTrapezoidal,
        ..MarchOptions::default()
    };
    let u = &u[..model.dofs() * (2 * h + 1)];
    let start = hb_state(model_half, h, 0.5 * omega, u, 0.0).unwrap();
    let snapshot = |m: &TimeMarcher| -> Vec<f64> {
        m.displacement()[..1]
            .iter()
            .chain(&m.velocity()[..1])
            .enumerate()
            .map(|(i, v)| if i == 0 { *v } else { v / omega })
            .collect()
    };
    let mut marcher = TimeMarcher::new(model, omega, &options, &start).unwrap();
    let y0 = snapshot(&marcher);
    let distance = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let mut at = Vec::new();
    for _ in 0..periods {
        for _ in 0..steps {
            marcher.step().unwrap();
        }
        at.push(distance(&snapshot(&marcher), &y0));
    }
    (at[1], at[0], at[periods - 1])
}

#[test]
fn the_period_two_branch_starts_where_the_marching_map_flips_and_marching_stays_on_it() {
    let structure = bilinear(20.0, 0.02, 0.0);
    let h = 20;
    let settings = SolverSettings {
        method: Method::SsnHb,
        max_iterations: 100,
        globalization: GlobalizationChoice::Nonmonotone,
        ..SolverSettings::with_harmonics(h)
    };
    let mut sweep = SweepSettings::new(1.5, 3.2);
    sweep.step = 0.02;
    sweep.period_two = true;
    let r = frequency_response(&structure, &settings, &sweep, None).unwrap();
    let event = r
        .events
        .iter()
        .find(|e| e.kind == BifurcationKind::PeriodDoubling)
        .expect("a period doubling");
    let (i, before) = (event.index, event.index - 1);
    let step = (r.points[i].omega - r.points[before].omega).abs();
    // Independent location: the most negative multiplier of the marching map's orbit
    // (shooting on the trapezoidal map with the contact node massless) at the two sweep
    // points around the event, interpolated to -1.
    let model = &structure.model;
    let det = |j: usize| map_flip_determinant(model, h, r.points[j].omega, &r.points[j].state);
    let (d0, d1) = (det(before), det(i));
    println!(
        "event {event:?}: map det(I + M) {d0:.4} at {:.4}, {d1:.4} at {:.4}",
        r.points[before].omega, r.points[i].omega
    );
    assert!(
        d0 * d1 < 0.0,
        "the map flips between the points: {d0}, {d1}"
    );
    let t = d0 / (d0 - d1);
    let marched = r.points[before].omega + t * (r.points[i].omega - r.points[before].omega);
    let outcome = r.period_two.first().expect("a period-2 branch");
    let PeriodTwoOutcome::Followed(branch) = outcome else {
        panic!("{outcome:?}");
    };
    println!(
        "marched flip {marched:.4}, event {:.4}, branch starts {:.4}, {} points, next {:?}, step {step:.4}",
        event.omega,
        branch.start_omega,
        branch.response.points.len(),
        branch.next_event
    );
    // The sweep's event and the switched branch's first point are within the sweep's step
    // of the marching map's flip (the harmonic-balance error of the multiplier, 1e-3
    // relative at H = 20, is well inside it).
    assert!(
        (event.omega - marched).abs() <= step,
        "{event:?} vs {marched}"
    );
    assert!(
        (branch.start_omega - marched).abs() <= step,
        "{} vs {marched}",
        branch.start_omega
    );
    assert_eq!(branch.period_multiple, 2);
    assert!(
        branch.response.points.len() >= 5,
        "{:?}",
        branch.response.termination
    );
    // The branch goes on to the next period doubling of the cascade and is cut there.
    let next = branch.next_event.expect("the next period doubling");
    assert_eq!(next.kind, BifurcationKind::PeriodDoubling);
    assert!(next.omega > branch.start_omega);
    let last = branch.response.points.last().unwrap();
    assert!(last.stability.stable == Some(false) && last.omega >= next.omega);
    // Stable points of the period-2 branch past the map's flip: marching from them returns
    // after 2T, not after T, and is still there 40 periods later.
    let half = on_half_frequency(model).unwrap();
    let stable: Vec<usize> = (0..branch.response.points.len())
        .filter(|&j| {
            let p = &branch.response.points[j];
            p.stability.stable == Some(true) && p.omega > marched + 0.01
        })
        .collect();
    assert!(stable.len() >= 3, "{stable:?}");
    for &j in stable.iter().step_by((stable.len() / 3).max(1)).take(3) {
        let p = &branch.response.points[j];
        let (two, one, late) = march_from(model, &half, branch.harmonics, p.omega, &p.state, 40);
        println!("period-2 point {j} at {:.4}: |y(2T)-y0| {two:.2e}, |y(T)-y0| {one:.2e}, after 40 T {late:.2e}", p.omega);
        // Measured: the return after 2T and after 40 T at most 1.5e-3 of the distance after
        // T (the march's orbit differs from the truncated one by the truncation error).
        assert!(
            two < 0.01 * one && late < 0.01 * one,
            "point {j}: {two}, {one}, {late}"
        );
    }
}
