//! Folds told apart from the zigzags of a piecewise-smooth branch: closed-form branches
//! whose kinks tip the parameter back and forth by less than the fold excursion, around
//! genuine folds whose position is known.

mod common;

use common::branches::Closure;
use semismooth::continuation::{
    Branch, Continuation, ContinuationOptions, ContinuationTermination,
};
use semismooth::linalg::FaerDenseLu;

/// Half-period of the sawtooth slope of [`wavy_s_curve`] (the distance between kinks).
const KINK_SPACING: f64 = 0.004;
/// Slope `±c` of the sawtooth of [`wavy_s_curve`].
const SAW_SLOPE: f64 = 0.5;

/// The sawtooth `w(x)`: slope `+c` on `[2jh, (2j+1)h)`, `-c` on `[(2j+1)h, (2j+2)h)`,
/// `w(0) = 0`, so `0 <= w <= c h`; and its slope.
fn saw(x: f64) -> (f64, f64) {
    let phase = (x / (2.0 * KINK_SPACING)).rem_euclid(1.0) * 2.0;
    if phase < 1.0 {
        (SAW_SLOPE * KINK_SPACING * phase, SAW_SLOPE)
    } else {
        (SAW_SLOPE * KINK_SPACING * (2.0 - phase), -SAW_SLOPE)
    }
}

/// `x^3 - x + w(x) - p = 0`: the S-curve with a kink every `h` where the slope of `w`
/// jumps by `2c`. The branch is the graph `p(x) = x^3 - x + w(x)` over `x`; where
/// `|3x^2 - 1| < c` its slope `3x^2 - 1 ± c` changes sign at every kink (a zigzag of
/// excursion at most `c h`), elsewhere the kinks keep `p` monotone. Its folds (net turns
/// of `p`) are within `c h` of the S-curve's, `p = ±2/(3√3)` (`0 <= w <= c h`).
fn wavy_s_curve() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0].powi(3) - x[0] + saw(x[0]).0 - p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0 + saw(x[0]).1),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

fn run(problem: &mut Closure, x0: f64, p0: f64, options: ContinuationOptions) -> Branch {
    let mut solver = FaerDenseLu::new();
    Continuation::new(problem, &mut solver, &[x0], p0, options)
        .unwrap()
        .run()
}

#[test]
fn kinks_that_tip_the_parameter_back_are_zigzags_and_the_folds_are_where_the_s_curve_turns() {
    // From p = -1 (x ≈ -1.32, the lower part) up through the upper fold, down the middle
    // part through the lower fold, up to p = 1.
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        ..ContinuationOptions::default()
    };
    let mut problem = wavy_s_curve();
    let branch = run(&mut problem, -1.3247, -1.0, options);
    let folds = branch.fold_parameters();
    println!(
        "{} points, folds {folds:?}, {} zigzags, corner passes {}",
        branch.points.len(),
        branch.zigzag_parameters().len(),
        branch.counters.corner_passes
    );
    assert!(matches!(
        branch.termination,
        ContinuationTermination::ReachedBound { bound: 1.0, .. }
    ));
    // Every point is on the branch (the corrector's tolerance on |F|).
    for q in &branch.points {
        let x = q.state[0];
        assert!((x.powi(3) - x + saw(x).0 - q.parameter).abs() <= 1e-10);
    }
    // The kinks are passed: exactly the S-curve's two folds, each within the sawtooth's
    // height c h = 0.002 of the closed form (0 <= w <= c h shifts the extremum of p by at
    // most that much), plus the fold's own resolution: the extreme point of steps of
    // θ-length <= 0.05 on a curve of curvature |p''| = 2√3 at the fold,
    // 3.5 (0.05 √2)² / 2 ≈ 1e-2 unrefined; 0.01 covers both (measured 1e-3 and 4.8e-3).
    let fold_s = 2.0 / (3.0 * 3f64.sqrt());
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!((folds[0] - fold_s).abs() < 0.01, "{}", folds[0] - fold_s);
    assert!((folds[1] + fold_s).abs() < 0.01, "{}", folds[1] + fold_s);
}

#[test]
fn steps_that_resolve_every_kink_still_find_only_the_two_folds() {
    // Steps below the kink spacing: the branch turns back at every kink of the zigzag
    // bands (|3x^2 - 1| < c: x in ±[0.408, 0.707], 75 kinks each), and every one of them
    // is seen.
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        initial_step: 0.001,
        min_step: 0.0002,
        max_step: 0.002,
        max_points: 20_000,
        ..ContinuationOptions::default()
    };
    let mut problem = wavy_s_curve();
    let branch = run(&mut problem, -1.3247, -1.0, options.clone());
    let folds = branch.fold_parameters();
    let zigzags = branch.zigzag_parameters().len();
    println!(
        "{} points, folds {folds:?}, {zigzags} zigzags",
        branch.points.len()
    );
    assert!(matches!(
        branch.termination,
        ContinuationTermination::ReachedBound { bound: 1.0, .. }
    ));
    // Two folds within c h = 0.002 of the closed form, plus what the Hermite refinement
    // can add across a kink: it may extrapolate past the extreme point by up to the
    // neighbouring increment, |Δp| <= 0.002 √2 (θ = 1/2); 0.005 bounds the sum (measured
    // 2.1e-3 and 1e-5).
    let fold_s = 2.0 / (3.0 * 3f64.sqrt());
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!((folds[0] - fold_s).abs() < 0.005, "{}", folds[0] - fold_s);
    assert!((folds[1] + fold_s).abs() < 0.005, "{}", folds[1] + fold_s);
    // The zigzags lie where the sawtooth can turn p back: |3x^2 - 1| < c, i.e. p within
    // the parameter range of x in ±[sqrt((1 - c)/3), sqrt((1 + c)/3)] (plus c h).
    let band = |x: f64| x.powi(3) - x;
    let (inner, outer) = (
        ((1.0 - SAW_SLOPE) / 3.0).sqrt(),
        ((1.0 + SAW_SLOPE) / 3.0).sqrt(),
    );
    let lowest = band(outer).min(band(inner)) - 0.002;
    for z in &branch.zigzag_parameters() {
        assert!(
            z.abs() >= lowest - 1e-12,
            "zigzag at {z} outside |p| >= {lowest}"
        );
    }
    // Most kinks of both bands are seen as zigzags (the others fall between two points).
    assert!(zigzags >= 100, "{zigzags}");
    // Without the excursion every reversal of the same points is a fold: the zigzags are
    // real reversals of the branch, and each is one fold there.
    let mut problem = wavy_s_curve();
    let every = run(
        &mut problem,
        -1.3247,
        -1.0,
        ContinuationOptions {
            fold_excursion: 0.0,
            ..options
        },
    );
    assert_eq!(every.parameters(), branch.parameters());
    assert!(every.zigzag_parameters().is_empty());
    assert_eq!(every.fold_parameters().len(), 2 + zigzags);
}

#[test]
fn a_fold_is_a_fold_when_the_branch_leaves_it_by_more_than_the_excursion() {
    // p = ε (x^3 - x): folds at ±ε 2/(3√3), an excursion of ε 4/(3√3) = 0.77 ε between
    // them. The default excursion is the θ-length 0.002, i.e. |Δp| = 0.002 √2 = 0.0028
    // (θ = 1/2, s_p = 1).
    let fold_s = 2.0 / (3.0 * 3f64.sqrt());
    let scaled = |eps: f64| Closure {
        n: 1,
        p: 0.0,
        f: Box::new(move |x, p, out| out[0] = eps * (x[0].powi(3) - x[0]) - p),
        j: Box::new(move |x, _, jac| jac[(0, 0)] = eps * (3.0 * x[0] * x[0] - 1.0)),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    };
    let options = ContinuationOptions {
        parameter_min: -0.5,
        parameter_max: 0.5,
        ..ContinuationOptions::default()
    };
    // Twice the excursion: two folds, at ±ε 2/(3√3) within the refined interpolation's
    // error (steps are mostly along x here, 1e-3 ε bounds it).
    let eps = 2.0 * 0.002 * 2f64.sqrt() / (2.0 * fold_s);
    let mut problem = scaled(eps);
    let branch = run(&mut problem, -1.5, eps * (-3.375 + 1.5), options.clone());
    let folds = branch.fold_parameters();
    println!(
        "ε = {eps}: folds {folds:?}, zigzags {:?}",
        branch.zigzag_parameters()
    );
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!((folds[0] - eps * fold_s).abs() < 1e-3 * eps);
    assert!((folds[1] + eps * fold_s).abs() < 1e-3 * eps);
    // Half the excursion: the turn back and forth is a zigzag, and no fold.
    let eps = 0.5 * 0.002 * 2f64.sqrt() / (2.0 * fold_s);
    let mut problem = scaled(eps);
    let branch = run(&mut problem, -1.5, eps * (-3.375 + 1.5), options);
    println!(
        "ε = {eps}: folds {:?}, zigzags {:?}",
        branch.fold_parameters(),
        branch.zigzag_parameters()
    );
    assert!(branch.fold_parameters().is_empty());
    assert_eq!(branch.zigzag_parameters().len(), 2);
}
