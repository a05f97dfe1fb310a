//! Corners of piecewise-affine branches, against branches known in closed form: crossed
//! exactly with the pieces known (`Continuation::with_affine_pieces`), and located within
//! one step by the plain continuation, which tells a corner fold from a sharp corner.

mod common;

use common::branches::*;

use semismooth::continuation::{
    Continuation, ContinuationEvent, ContinuationOptions, ContinuationTermination, PiecewiseAffine,
    Predictor,
};
use semismooth::faer::Mat;
use semismooth::linalg::FaerDenseLu;
use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};

/// `F(x, p) = p + sum_i |x - c_i| * w_i - b x` in one unknown: the branch `p(x)` is
/// piecewise linear with a corner at every `c_i`. Switching functions `s_i = x - c_i`; on
/// the piece `h` the residual is `p + sum_i (+-)(x - c_i) w_i - b x`.
struct Kinks {
    centers: Vec<f64>,
    weights: Vec<f64>,
    slope: f64,
    p: f64,
    held: Option<Vec<bool>>,
}

impl Kinks {
    /// `d|x - c_i|/dx` on the piece held, or at `x`.
    fn signs(&self, x: f64) -> Vec<f64> {
        self.centers
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let on = match &self.held {
                    Some(h) => h[i],
                    None => x - c > 0.0,
                };
                if on {
                    1.0
                } else {
                    -1.0
                }
            })
            .collect()
    }
}

impl Residual for Kinks {
    fn dim(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let signs = self.signs(x[0]);
        out[0] = self.p - self.slope * x[0]
            + self
                .centers
                .iter()
                .zip(&self.weights)
                .zip(&signs)
                .map(|((c, w), s)| s * (x[0] - c) * w)
                .sum::<f64>();
        Ok(())
    }
}

impl GeneralizedJacobian for Kinks {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(1, 1)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        let signs = self.signs(x[0]);
        jac[(0, 0)] = -self.slope
            + self
                .weights
                .iter()
                .zip(&signs)
                .map(|(w, s)| w * s)
                .sum::<f64>();
        Ok(())
    }
}

impl ParameterDependent for Kinks {
    fn parameter(&self) -> f64 {
        self.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.p = p;
    }
    fn residual_parameter_derivative(
        &mut self,
        _: &[f64],
        out: &mut [f64],
        _: &mut [f64],
    ) -> Result<(), EvaluationError> {
        out[0] = 1.0;
        Ok(())
    }
}

impl PiecewiseAffine for Kinks {
    fn switching_count(&self) -> usize {
        self.centers.len()
    }
    fn switching(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        for (o, c) in out.iter_mut().zip(&self.centers) {
            *o = x[0] - c;
        }
        Ok(())
    }
    fn hold_piece(&mut self, piece: Option<&[bool]>) {
        self.held = piece.map(<[bool]>::to_vec);
    }
}

fn options() -> ContinuationOptions {
    ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        ..Default::default()
    }
}

/// `p + |x| = 0`: up the left side, the corner at (0, 0), down the right side. Crossed
/// exactly, the corner is a branch point at `x = 0` to round-off and the one fold is at
/// `p = 0` to round-off (the corner passes without the capability report it within one
/// step of the corner, `tests/continuation.rs`).
#[test]
fn roof_corner_is_located_exactly_and_is_the_fold() {
    let mut problem = Kinks {
        centers: vec![0.0],
        weights: vec![1.0],
        slope: 0.0,
        p: -1.0,
        held: None,
    };
    let mut solver = FaerDenseLu::new();
    let branch = Continuation::new(&mut problem, &mut solver, &[-1.0], -1.0, options())
        .unwrap()
        .with_affine_pieces()
        .run();
    assert_eq!(
        branch.termination,
        ContinuationTermination::ReachedBound {
            parameter: -1.0,
            bound: -1.0
        }
    );
    for point in &branch.points {
        assert!((point.parameter + point.state[0].abs()).abs() < 1e-12);
    }
    let corners: Vec<_> = branch.points.iter().filter(|p| p.corner).collect();
    assert_eq!(corners.len(), 1);
    assert!(corners[0].state[0].abs() < 1e-12 && corners[0].parameter.abs() < 1e-12);
    assert_eq!(branch.corner_parameters().len(), 1);
    let folds = branch.fold_parameters();
    assert_eq!(folds.len(), 1, "{folds:?}");
    assert!(folds[0].abs() < 1e-12, "{}", folds[0]);
    assert_eq!(branch.counters.corners, 1);
}

/// A zigzag branch `p = x / 2 - sum_i w_i |x - c_i|` with three corners close together
/// (0.1, 0.13, 0.16: closer than one largest step) and turns at each: the walk crosses
/// them in one go, every corner is a branch point at its exact position, the folds are the
/// corners where `p` reverses, and every point lies on the branch.
#[test]
fn chain_of_close_corners_is_walked_in_one_go() {
    let centers = vec![0.1, 0.13, 0.16];
    let weights = vec![1.0, -1.0, 1.0];
    let mut problem = Kinks {
        centers: centers.clone(),
        weights: weights.clone(),
        slope: 0.5,
        p: -1.0,
        held: None,
    };
    // p(x) on the branch: p = 0.5 x - sum w_i |x - c_i|.
    let p_of = |x: f64| {
        0.5 * x
            - centers
                .iter()
                .zip(&weights)
                .map(|(c, w)| w * (x - c).abs())
                .sum::<f64>()
    };
    let x0 = -2.0;
    let p0 = p_of(x0);
    let mut solver = FaerDenseLu::new();
    let branch = Continuation::new(
        &mut problem,
        &mut solver,
        &[x0],
        p0,
        ContinuationOptions {
            parameter_min: p0,
            parameter_max: 1.0,
            ..Default::default()
        },
    )
    .unwrap()
    .with_affine_pieces()
    .run();
    println!(
        "{} points, corners {:?}, folds {:?}, {}",
        branch.points.len(),
        branch.corner_parameters(),
        branch.fold_parameters(),
        branch.termination
    );
    for point in &branch.points {
        assert!((point.parameter - p_of(point.state[0])).abs() < 1e-12);
    }
    let corner_states: Vec<f64> = branch
        .points
        .iter()
        .filter(|p| p.corner)
        .map(|p| p.state[0])
        .collect();
    assert_eq!(corner_states.len(), 3, "{corner_states:?}");
    for (x, c) in corner_states.iter().zip(&centers) {
        assert!((x - c).abs() < 1e-12, "{x} vs {c}");
    }
    // Slopes dp/dx: 0.5 + (1 - 1 + 1) = 1.5 left of 0.1, then -0.5, 1.5, -0.5: p turns at
    // 0.1 (max) and 0.13 (min) and 0.16 (max): three folds, all at corners.
    let folds = branch.fold_parameters();
    assert_eq!(folds.len(), 3, "{folds:?}");
    for (f, c) in folds.iter().zip(&centers) {
        assert!((f - p_of(*c)).abs() < 1e-12, "{f} vs {}", p_of(*c));
    }
    assert!(branch.events.iter().all(|e| matches!(
        e,
        ContinuationEvent::Fold { .. } | ContinuationEvent::Corner { .. }
    )));
}

/// `p + |x| = 0`: the branch `p = -|x|` turns back at a corner (`x = 0`, `p = 0`), where
/// the generalized Jacobian jumps from `-1` to `1` and no tangent exists.
fn roof() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = p + x[0].abs()),
        j: Box::new(|x, _, jac| jac[(0, 0)] = if x[0] >= 0.0 { 1.0 } else { -1.0 }),
        fp: Some(Box::new(|_, _, out| out[0] = 1.0)),
    }
}

/// Slope of [`steep_corner`]'s two pieces.
const STEEP: f64 = 20.0;

/// `x + STEEP |p| = 0`: a graph over `p` (so no fold) with a corner at `p = 0` where the
/// branch turns by nearly 180° in the `(x, p)` plane.
fn steep_corner() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] + STEEP * p.abs()),
        j: Box::new(|_, _, jac| jac[(0, 0)] = 1.0),
        fp: Some(Box::new(|_, p, out| out[0] = STEEP * p.signum())),
    }
}

#[test]
fn corner_fold_of_a_piecewise_linear_branch_is_reported_within_one_step_of_the_corner() {
    let options = between(-1.0, 1.0);
    let branch = follow(&mut roof(), &[-1.0], -1.0, options.clone());
    // Up the left side, over the corner, down the right side to the bound p = -1 at x = 1.
    let last = branch.points.last().unwrap();
    assert_eq!(
        branch.termination,
        ContinuationTermination::ReachedBound {
            parameter: -1.0,
            bound: -1.0
        }
    );
    assert!((last.state[0] - 1.0).abs() < 1e-12, "{}", last.state[0]);
    for point in &branch.points {
        assert!((point.parameter + point.state[0].abs()).abs() < 1e-10);
    }
    let folds = branch.fold_parameters();
    println!(
        "roof: {} points, folds {folds:?}, corner passes {}, rejected steps {}",
        branch.points.len(),
        branch.counters.corner_passes,
        branch.counters.rejected_steps
    );
    assert_eq!(folds.len(), 1, "{folds:?}");
    // The fold is at p = 0; the neighbouring points are within one (θ-norm) step, i.e.
    // |Δp| <= max_step / sqrt(1 - θ), of it, and the report is never past the corner.
    let reach = options.max_step / (1.0 - options.theta).sqrt();
    assert!(folds[0] <= 1e-12 && folds[0] > -reach, "{}", folds[0]);
    let ContinuationEvent::Fold { index, .. } = branch.events[0] else {
        unreachable!()
    };
    // The highest point of the branch is the fold's extreme point or its neighbour.
    let top = branch
        .points
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.parameter.total_cmp(&b.1.parameter))
        .unwrap()
        .0;
    assert!(index.abs_diff(top) <= 1, "fold at {index}, top at {top}");
    assert!(branch.counters.corner_passes >= 1);
}

#[test]
fn sharp_corner_of_a_graph_over_the_parameter_is_passed_without_a_fold() {
    for predictor in [Predictor::Secant, Predictor::Tangent] {
        let mut problem = steep_corner();
        let mut solver = FaerDenseLu::new();
        let options = ContinuationOptions {
            parameter_min: -1.0,
            parameter_max: 1.0,
            predictor,
            ..Default::default()
        };
        let branch = Continuation::new(&mut problem, &mut solver, &[-STEEP], -1.0, options)
            .unwrap()
            .run();
        let parameters = branch.parameters();
        println!(
            "{predictor:?}: {} points, corner passes {}, rejected steps {}",
            parameters.len(),
            branch.counters.corner_passes,
            branch.counters.rejected_steps
        );
        // The branch is a graph over p: p increases at every point, to the bound p = 1.
        assert!(parameters.windows(2).all(|w| w[1] > w[0]));
        assert_eq!(
            branch.termination,
            ContinuationTermination::ReachedBound {
                parameter: 1.0,
                bound: 1.0
            }
        );
        assert!((branch.points.last().unwrap().state[0] + STEEP).abs() < 1e-10);
        assert_eq!(fold_count(&branch), 0, "{:?}", branch.events);
        assert!(branch.counters.corner_passes >= 1);
    }
    // Pseudo-arclength alone cannot cut the far side of a corner turning by more than 90°
    // in the θ-norm: without the corner passes the run stops there.
    let mut problem = steep_corner();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        pass_corners: false,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[-STEEP], -1.0, options)
        .unwrap()
        .run();
    let end = branch.points.last().unwrap().parameter;
    assert!(end < 0.0 && end > -0.01, "{:?}", branch.termination);
    assert!(matches!(
        branch.termination,
        ContinuationTermination::TooManyFailures { .. }
            | ContinuationTermination::StepTooSmall { .. }
    ));
}

#[test]
fn fold_detector_confirms_reversals_and_ignores_unconfirmed_tangent_flips() {
    use semismooth::continuation::FoldDetector;
    // p = sin(s) sampled every 0.3 with exact tangents: one fold at p = 1 (s = π/2).
    let mut detector = FoldDetector::new(true);
    let mut events = Vec::new();
    for k in 0..12 {
        let s = 0.3 * k as f64;
        events.extend(detector.push(s.sin(), s.cos(), 0.3));
    }
    events.extend(detector.finish());
    assert_eq!(events.len(), 1, "{events:?}");
    let ContinuationEvent::Fold { index, parameter } = events[0] else {
        unreachable!()
    };
    // Between s = 1.5 (k = 5) and 1.8 (k = 6); Hermite error over h = 0.3 ~ h^4/384.
    assert_eq!(index, 6);
    assert!((parameter - 1.0).abs() < 1e-4, "{parameter}");
    // A tangent that flips sign without the parameter turning back is no fold; a reversal
    // with no sign change of the tangent (a corner) is a fold at the extreme point.
    let mut detector = FoldDetector::new(true);
    let pushed: Vec<_> = [(0.0, 1.0), (0.1, -1.0), (0.2, 1.0), (0.3, 1.0), (0.25, 1.0)]
        .iter()
        .flat_map(|&(p, t)| detector.push(p, t, 0.1))
        .collect();
    assert_eq!(
        pushed,
        vec![ContinuationEvent::Fold {
            index: 3,
            parameter: 0.3
        }]
    );
}
