//! Exact 3-D Coulomb–Signorini time marching (Moreau–Jean, the normal law and the disk
//! solved together per step) against SSN-HB on an oscillator with two tangential dofs and
//! one normal dof: stick-slip with a turning slip direction, and liftoff. The march is
//! first order (`theta = 1` for the massless normal dof), so its reference is the
//! Richardson extrapolation `2 m(8000) - m(4000)` of 4000 and 8000 steps per period.

#[path = "common/disk_march.rs"]
mod disk_march;

use disk_march::{extrapolated, harmonic_balance, march, Case, Measures, LIFTOFF, STICK_SLIP};

/// HB at H = 10, 20, 40 against the extrapolated march, and the march at 8000 steps.
fn differences(case: &Case) -> (Vec<f64>, Measures, Measures) {
    let coarse = march(case, 4000);
    let fine = march(case, 8000);
    let reference = extrapolated(&coarse, &fine);
    let mut at_40 = None;
    let differences = [10, 20, 40]
        .iter()
        .map(|&h| {
            let hb = harmonic_balance(case, h);
            let difference = hb.difference(&reference);
            at_40 = Some(hb);
            difference
        })
        .collect();
    eprintln!(
        "{}: HB against the extrapolated march at H = 10, 20, 40: {differences:?}; march at \
         8000 steps against it: {:.2e}",
        case.name,
        fine.difference(&reference)
    );
    (differences, at_40.unwrap(), fine)
}

/// Whether a tangential force series turns: each component takes both signs.
fn turns(force: &[Vec<f64>; 2]) -> bool {
    force.iter().all(|f| {
        let (lo, hi) = f
            .iter()
            .fold((0.0f64, 0.0f64), |(a, b), v| (a.min(*v), b.max(*v)));
        lo < 0.0 && hi > 0.0
    })
}

/// HB's difference to the march at H = 10, 20, 40 falls by 8 from H = 10 to 40 and below
/// 1e-3 at H = 40 (the justification above the tests).
fn assert_converges(differences: &[f64]) {
    assert!(differences[2] < differences[0] / 8.0, "{differences:?}");
    assert!(differences[2] < 1e-3, "{differences:?}");
}

// Tolerances: the march at 8000 steps is within 5e-3 of its extrapolation (first order);
// the extrapolation removes that term, leaving a second-order remainder of order 1e-4
// (the liftoff and stick instants are quantised by the step). HB converges to it: measured
// 2.8e-3, 8.8e-4, 6.1e-5 (stick-slip) and 3.4e-3, 1.3e-3, 3.5e-4 (liftoff) at H = 10, 20, 40.
// Asserted: a factor 8 from H = 10 to 40, and within 1e-3 at H = 40.

#[test]
fn harmonic_balance_converges_to_the_exact_3d_march_through_stick_slip_with_a_turning_slip() {
    let (differences, hb, fine) = differences(&STICK_SLIP);
    assert_converges(&differences);
    for report in [&hb.report, &fine.report] {
        assert!(report.stick_fraction > 0.05, "{report:?}");
        assert_eq!(report.separated_fraction, 0.0);
        assert!(turns(&report.tangential_force));
    }
}

#[test]
fn harmonic_balance_converges_to_the_exact_3d_march_through_liftoff() {
    let (differences, hb, fine) = differences(&LIFTOFF);
    assert_converges(&differences);
    for report in [&hb.report, &fine.report] {
        assert!(report.separated_fraction > 0.2, "{report:?}");
        assert!(turns(&report.tangential_force));
    }
    // The liftoff fractions agree to the march's step and HB's truncation (0.288 and 0.285).
    assert!((hb.report.separated_fraction - fine.report.separated_fraction).abs() < 0.01);
}
