//! A branch taken up on another discretisation of the same equations
//! ([`Continuation::resume`]): the S-curve `x0^3 - x0 - p = 0` carried by `n` unknowns, the
//! others slaved to it (`x_i = x0 / (i + 1)^2`), switched from one to three unknowns before
//! its first fold and back to one between its folds. Both folds are found at their closed
//! form `p = ±2/(3√3)`, across the switches, as accurately as by an uninterrupted run.

mod common;

use common::branches::{Closure, FOLD_S};
use semismooth::continuation::{
    Continuation, ContinuationEvent, ContinuationOptions, ContinuationTermination, Resumption,
};
use semismooth::linalg::FaerDenseLu;

/// The S-curve in `n` unknowns: `x0^3 - x0 - p = 0`, `x_i - x0 / (i + 1)^2 = 0`.
fn slaved_s_curve(n: usize) -> Closure {
    shifted_s_curve(n, 0.0)
}

/// The S-curve moved by `shift` in the parameter: `x0^3 - x0 - p - shift = 0` (folds at
/// `p = ±2/(3√3) - shift`), the other unknowns slaved as in [`slaved_s_curve`].
fn shifted_s_curve(n: usize, shift: f64) -> Closure {
    Closure {
        n,
        p: 0.0,
        f: Box::new(move |x, p, out| {
            out[0] = x[0].powi(3) - x[0] - p - shift;
            for i in 1..x.len() {
                out[i] = x[i] - x[0] / ((i + 1) * (i + 1)) as f64;
            }
        }),
        j: Box::new(|x, _, jac| {
            jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0;
            for i in 1..x.len() {
                jac[(i, 0)] = -1.0 / ((i + 1) * (i + 1)) as f64;
                jac[(i, i)] = 1.0;
            }
        }),
        fp: Some(Box::new(|x, _, out| {
            out.iter_mut().for_each(|o| *o = 0.0);
            out[0] = -1.0;
            let _ = x;
        })),
    }
}

/// The options for `n` unknowns, with state scales that make the θ-norm the same function
/// of `x0` whatever `n` (`s_0 = 1/√n`; the slaved unknowns weigh nothing), as the sweeps'
/// scaling does for harmonics.
fn options(n: usize) -> ContinuationOptions {
    let mut scale = vec![1e6; n];
    scale[0] = 1.0 / (n as f64).sqrt();
    ContinuationOptions {
        state_scale: Some(scale),
        parameter_min: -1.0,
        parameter_max: 1.0,
        max_step: 0.1,
        refine_folds: true,
        ..Default::default()
    }
}

/// `v` with its state part carried from `from` to `to` unknowns: truncated, or padded
/// with zeros (the caller's "lift"); a direction keeps its parameter component last.
fn carry(v: &[f64], from: usize, to: usize, parameter_last: bool) -> Vec<f64> {
    let mut out: Vec<f64> = (0..to).map(|i| if i < from { v[i] } else { 0.0 }).collect();
    if parameter_last {
        out.push(v[from]);
    }
    out
}

fn carried(r: Resumption, from: usize, to: usize) -> Resumption {
    Resumption {
        state: carry(&r.state, from, to, false),
        direction: carry(&r.direction, from, to, true),
        ..r
    }
}

fn folds(events: &[ContinuationEvent]) -> Vec<(usize, f64)> {
    events
        .iter()
        .filter_map(|e| match e {
            ContinuationEvent::Fold { index, parameter } => Some((*index, *parameter)),
            _ => None,
        })
        .collect()
}

#[test]
fn a_branch_switched_between_discretisations_finds_both_folds_at_their_closed_form() {
    // Uninterrupted, with three unknowns: the reference for the fold locations' accuracy.
    let mut whole = slaved_s_curve(3);
    let mut solver = FaerDenseLu::new();
    let start = [-1.3, -1.3 / 4.0, -1.3 / 9.0];
    let branch = Continuation::new(&mut whole, &mut solver, &start, -0.897, options(3))
        .unwrap()
        .run();
    let reference = branch.fold_parameters();
    assert_eq!(reference.len(), 2, "{:?}", branch.events);
    let reference_error = (reference[0] - FOLD_S)
        .abs()
        .max((reference[1] + FOLD_S).abs());

    // One unknown up to p = 0.3, before the first fold.
    let mut events = Vec::new();
    let mut parameters = Vec::new();
    let mut one = slaved_s_curve(1);
    let mut run = Continuation::new(&mut one, &mut solver, &[-1.3], -0.897, options(1)).unwrap();
    let mut resumption = None;
    for point in run.by_ref() {
        parameters.push(point.parameter);
        if point.parameter > 0.3 {
            resumption = run.resumption();
            break;
        }
    }
    events.extend_from_slice(run.events());
    drop(run);
    let resumption = resumption.expect("a point past p = 0.3");
    let points_before = resumption.points;
    assert_eq!(points_before, parameters.len());

    // Three unknowns (padded with zeros) over the first fold, down to p = 0.
    let mut three = slaved_s_curve(3);
    let mut run = Continuation::resume(
        &mut three,
        &mut solver,
        carried(resumption, 1, 3),
        options(3),
    )
    .unwrap();
    let first = run.next().expect("the resumed point");
    // The resumed point replaces the last one: the same point of the curve (the slaved
    // unknowns weigh nothing in the metric, so the hyperplane only fixes x0 and p, which
    // already solve the cubic to the corrector's tolerance 1e-10: p moves by less), the
    // padding corrected.
    let moved = (first.parameter - parameters.last().unwrap()).abs();
    assert!(moved < 1e-10, "moved by {moved:e}");
    assert!((first.state[1] - first.state[0] / 4.0).abs() < 1e-9);
    assert!((first.state[2] - first.state[0] / 9.0).abs() < 1e-9);
    let mut resumption = None;
    for point in run.by_ref() {
        parameters.push(point.parameter);
        if point.parameter < 0.0 && parameters.len() > points_before + 3 {
            resumption = run.resumption();
            break;
        }
    }
    events.extend_from_slice(run.events());
    drop(run);
    let resumption = resumption.expect("a point past the first fold");
    assert_eq!(resumption.points, parameters.len());

    // One unknown again (truncated) to the end.
    let mut one = slaved_s_curve(1);
    let mut run =
        Continuation::resume(&mut one, &mut solver, carried(resumption, 3, 1), options(1)).unwrap();
    run.next().expect("the resumed point");
    for point in run.by_ref() {
        parameters.push(point.parameter);
    }
    events.extend_from_slice(run.events());
    assert!(
        matches!(
            run.termination(),
            Some(ContinuationTermination::ReachedBound { bound, .. }) if *bound == 1.0
        ),
        "{:?}",
        run.termination()
    );

    let found = folds(&events);
    assert_eq!(found.len(), 2, "{events:?}");
    // The indices count the stitched branch's points: each fold is the extreme point or
    // the one after it.
    for &(index, _) in &found {
        let extreme = parameters[index]
            .abs()
            .max(parameters[index.saturating_sub(1)].abs());
        assert!(extreme <= FOLD_S + 1e-12 && extreme > 0.3, "{found:?}");
    }
    // Located by Hermite interpolation on steps of at most 0.1: as accurate as the
    // uninterrupted run's (3.5e-4, a cubic's error on steps of that size; the stitched
    // run's steps differ, hence a factor 2).
    for (&(_, parameter), exact) in found.iter().zip([FOLD_S, -FOLD_S]) {
        let error = (parameter - exact).abs();
        assert!(
            error <= 2.0 * reference_error,
            "fold {parameter} (exact {exact}): error {error:e}, uninterrupted {reference_error:e}"
        );
    }
}

#[test]
fn a_branch_resumed_past_the_new_discretisations_fold_is_taken_up_on_the_same_branch() {
    // The branch with one unknown, in steps of at most 0.01, up to p > 0.36 on the lower
    // sheet (x0 < -1/√3), just before its fold 2/(3√3) = 0.3849.
    let fine = |n| ContinuationOptions {
        max_step: 0.01,
        ..options(n)
    };
    let mut solver = FaerDenseLu::new();
    let mut one = slaved_s_curve(1);
    let mut run = Continuation::new(&mut one, &mut solver, &[-1.3], -0.897, fine(1)).unwrap();
    let mut resumption = None;
    for point in run.by_ref() {
        if point.parameter > 0.36 && point.state[0] < -1.0 / 3f64.sqrt() {
            resumption = run.resumption();
            break;
        }
    }
    drop(run);
    let resumption = resumption.expect("a point past p = 0.36 on the lower sheet");
    let (x_old, p_old) = (resumption.state[0], resumption.parameter);
    assert!(x_old < -1.0 / 3f64.sqrt() && p_old < FOLD_S);

    // Three unknowns whose curve is moved by 0.03: its lower sheet ends at the fold
    // FOLD_S - 0.03 < p_old, so no solution of the new problem is near the point at its
    // parameter (the nearest at p_old is on the upper sheet, x0 > 1). On the hyperplane
    // normal to the carried direction the point is taken up on the lower sheet, near the
    // new fold, and the run turns there.
    let shift = 0.03;
    let mut three = shifted_s_curve(3, shift);
    let mut run =
        Continuation::resume(&mut three, &mut solver, carried(resumption, 1, 3), fine(3)).unwrap();
    let first = run.next().expect("the resumed point");
    let x0 = first.state[0];
    let residual = x0.powi(3) - x0 - first.parameter - shift;
    assert!(residual.abs() < 1e-9, "residual {residual:e}");
    // On the same (lower) sheet, moved by less than the shift.
    assert!(x0 < 0.0 && (x0 - x_old).abs() < 0.2, "x0 {x0} from {x_old}");
    assert!(first.parameter < FOLD_S - shift, "p {} ", first.parameter);
    assert!((first.parameter - p_old).abs() < 2.0 * shift);
    let mut parameters = vec![first.parameter];
    for point in run.by_ref() {
        parameters.push(point.parameter);
        if parameters.len() > 10 {
            break;
        }
    }
    let found = folds(run.events());
    assert!(!found.is_empty(), "{:?} {parameters:?}", run.events());
    let error = (found[0].1 - (FOLD_S - shift)).abs();
    // Hermite location on steps of at most 0.01: at least as accurate as the uninterrupted
    // run's on steps of 0.1 (3.5e-4).
    assert!(
        error < 3.5e-4,
        "fold {} (exact {}): {error:e}",
        found[0].1,
        FOLD_S - shift
    );
}
