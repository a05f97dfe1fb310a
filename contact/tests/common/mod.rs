//! Helpers shared by the integration tests (each test that uses them declares `mod common;`
//! and uses a part): the canonical rods and solver settings, solves that must converge,
//! dense copies of the sparse model matrices and the exact linear response computed from
//! them (a dense complex solve, independent of the code under test), vector norms, and a
//! per-thread allocation counter.

#![allow(dead_code)]

pub mod periodic;

use nalgebra::{Complex, DMatrix, DVector};
use semismooth::newton::{Globalization, NewtonOptions, NewtonReport, Tolerances};
use semismooth::polyalgorithm::{SmoothingOf, SolveOptions};
use semismooth::{Factorize, GeneralizedJacobian};
use semismooth_contact::hb::{HbOptions, SsnHb};
use semismooth_contact::model::{SparseMatrix, StructuralModel};
use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodModel, RodSpec};
use semismooth_contact::settings::{
    default_hb_time_samples, GlobalizationChoice, Method, SolverSettings, SweepSettings,
};
use semismooth_contact::solve::{solve, RunError, Solution};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

/// The `n x n` sparse matrix with the `(row, column, value)` entries.
pub fn sparse(n: usize, entries: &[(usize, usize, f64)]) -> SparseMatrix {
    semismooth_contact::builder::sparse_matrix(n, entries).unwrap()
}

/// The canonical rod of the paper's Fig. 1 (20 elements, tip gap 0.5, forced at
/// `omega_1`) with the mass model `mass`.
pub fn canonical(mass: MassModel) -> RodSpec {
    RodSpec {
        mass,
        ..RodSpec::canonical()
    }
}

/// The canonical modified-mass rod (massless contact node) refined to `elements`, with
/// its contact at the tip, gap `gap`.
pub fn refined(elements: usize, gap: f64) -> RodSpec {
    RodSpec {
        elements,
        contacts: vec![RodContact {
            node: elements,
            gap,
        }],
        ..canonical(MassModel::Modified)
    }
}

/// The rod of Fig. 2 (tip contact at `gap`, or none) forced with `amplitude`, mass model
/// `mass`, built.
pub fn fig2_rod_model(gap: Option<f64>, amplitude: f64, mass: MassModel) -> RodModel {
    build_rod(&RodSpec {
        amplitude,
        mass,
        ..RodSpec::canonical().with_tip_gap(gap)
    })
    .unwrap()
}

/// The settings of the frequency sweeps: the defaults of `method` with `harmonics`, at
/// most 100 Newton iterations with the non-monotone line search, 1024 time steps per period.
pub fn sweep_solver(method: Method, harmonics: usize) -> SolverSettings {
    SolverSettings {
        method,
        max_iterations: 100,
        globalization: GlobalizationChoice::Nonmonotone,
        steps_per_period: 1024,
        ..SolverSettings::with_harmonics(harmonics)
    }
}

/// The time-marching reference: `steps` per period, marched until the period-to-period
/// change is below `tolerance`.
pub fn march(steps: usize, tolerance: f64) -> SolverSettings {
    SolverSettings {
        method: Method::March,
        steps_per_period: steps,
        march_tolerance: tolerance,
        ..SolverSettings::with_harmonics(20)
    }
}

/// Solves `rod` at its spec's frequency with `settings`; fails the test unless the solve
/// converged.
pub fn solve_converged(rod: &RodModel, settings: &SolverSettings) -> Solution {
    let s = solve(rod, rod.omega(), settings, None).unwrap();
    assert!(
        s.converged(),
        "{} H = {} Nt = {} c = {:?}: {} ({} iterations)",
        settings.method.name(),
        settings.harmonics,
        settings.time_samples,
        settings.c,
        s.termination,
        s.iterations
    );
    s
}

/// Newton (plain or the polyalgorithm, with the problem's `smoothing` when given) from `x`
/// (overwritten by the root); fails the test, naming `what`, unless it converged.
pub fn newton_converged<P, S>(
    what: &str,
    problem: &mut P,
    solver: &mut S,
    x: &mut [f64],
    (options, smoothing): (&SolveOptions, Option<SmoothingOf<P>>),
) -> NewtonReport
where
    P: GeneralizedJacobian + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    let report = options
        .solve(problem, solver, x, smoothing)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(report.converged(), "{what}: {:?}", report.termination);
    report
}

/// A dense copy of a sparse model matrix.
pub fn dense(m: &SparseMatrix) -> DMatrix<f64> {
    let r = m.as_ref();
    let mut d = DMatrix::zeros(r.nrows(), r.ncols());
    for j in 0..r.ncols() {
        for (i, v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            d[(i, j)] += v;
        }
    }
    d
}

/// Dense `K`, `M`, `D` (zero when undamped).
pub fn dense_kmd(model: &StructuralModel) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let k = dense(&model.stiffness);
    let d = model
        .damping
        .as_ref()
        .map(dense)
        .unwrap_or_else(|| DMatrix::zeros(k.nrows(), k.ncols()));
    (k, dense(&model.mass), d)
}

/// The exact complex amplitude `z` of the linear steady response without contact,
/// `(K - w^2 M + i w D) z = f`, `u(t) = Re(z e^{i w t}) = Re z cos(w t) - Im z sin(w t)`
/// (dense complex LU).
pub fn exact_linear(model: &StructuralModel, w: f64) -> DVector<Complex<f64>> {
    let (k, m, d) = dense_kmd(model);
    let a = DMatrix::from_fn(k.nrows(), k.ncols(), |i, j| {
        Complex::new(k[(i, j)] - w * w * m[(i, j)], w * d[(i, j)])
    });
    let load = model.load.forcing_cosine();
    let f = DVector::from_fn(k.nrows(), |i, _| Complex::new(load[i], 0.0));
    a.lu().solve(&f).expect("regular dynamic stiffness")
}

/// Euclidean norm.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Largest absolute entry (0 for an empty slice).
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| m.max(x.abs()))
}

/// Largest absolute difference of two slices, entry by entry.
/// Largest gap between `solution`'s observed-dof history and the exact linear response
/// `Re(z e^{i w t})` of its dof `dof` at its frequency `w` (no contact closing); returns
/// `(gap, |z|)`.
pub fn linear_history_error(
    model: &StructuralModel,
    dof: usize,
    solution: &semismooth_contact::solve::Solution,
) -> (f64, f64) {
    let w = solution.omega;
    let z = exact_linear(model, w)[dof];
    let exact: Vec<f64> = solution
        .times
        .iter()
        .map(|t| z.re * (w * t).cos() - z.im * (w * t).sin())
        .collect();
    (max_abs_diff(&solution.observed, &exact), z.norm())
}

pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// `|a - b| / |b|`.
pub fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[path = "../../../tests/common/mod.rs"]
mod allocation;
#[allow(unused_imports)]
pub use allocation::*;

/// SSN-HB on `model` forced at `omega` with `harmonics`, the default AFT samples for them
/// and the default complementarity constant.
pub fn ssn_hb(model: &StructuralModel, omega: f64, harmonics: usize) -> SsnHb {
    let options = HbOptions {
        harmonics,
        time_samples: Some(default_hb_time_samples(harmonics)),
        c: None,
    };
    SsnHb::new(model, omega, &options).unwrap()
}

/// Plain Newton (full steps, at most 20 iterations) to `|F| <= 1e-12`: re-solving from a
/// point already on a branch must converge at once and not move it.
pub fn plain_newton() -> SolveOptions {
    SolveOptions::Newton(NewtonOptions {
        tolerances: Tolerances::absolute(1e-12),
        max_iterations: 20,
        globalization: Globalization::None,
    })
}

/// The frequency response of `rod` with `settings` over `omega / omega_1` in `[0.5, 2]`
/// (the interval of Fig. 2) with the scene's default steps.
pub fn sweep_fig2_interval(
    rod: &RodModel,
    settings: &SolverSettings,
) -> Result<FrequencyResponse, RunError> {
    frequency_response(rod, settings, &SweepSettings::new(0.5, 2.0), None)
}

/// The amplitude `sqrt(a_1^2 + b_1^2)` of the first harmonic of `N` equally spaced
/// samples of one period (the trapezoidal rule, exact for a trigonometric polynomial of
/// degree `< N - 1`).
pub fn first_harmonic(u: &[f64]) -> f64 {
    let n = u.len() as f64;
    let (mut a, mut b) = (0.0, 0.0);
    for (j, v) in u.iter().enumerate() {
        let phase = 2.0 * std::f64::consts::PI * j as f64 / n;
        a += v * phase.cos();
        b += v * phase.sin();
    }
    2.0 * a.hypot(b) / n
}

/// The backbone of mode 1 of `model` over the amplitude `from..to` of dof 0 with
/// `harmonics` harmonics, asserted to reach the end of the range, and the EPMC problem its
/// points are read with.
pub fn mode_one_backbone(
    model: &StructuralModel,
    from: f64,
    to: f64,
    harmonics: usize,
) -> (
    semismooth_contact::modes::Backbone,
    semismooth_contact::modes::Epmc,
) {
    use semismooth::continuation::ContinuationTermination;
    use semismooth_contact::modes::{backbone, AmplitudeMeasure, BackboneOptions, Epmc};
    let mut options = BackboneOptions::new(1, AmplitudeMeasure::Dof(0), from, to);
    options.hb.harmonics = harmonics;
    let branch = backbone(model, &options).unwrap();
    assert!(
        matches!(
            branch.termination,
            ContinuationTermination::ReachedBound { .. }
        ),
        "H = {harmonics}: {:?}",
        branch.termination
    );
    let epmc = Epmc::new(model, &options.hb, 1, AmplitudeMeasure::Dof(0)).unwrap();
    (branch, epmc)
}
