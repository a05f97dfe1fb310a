//! The period-2 branch born at a period doubling of a frequency-response branch.
//!
//! At a period doubling a real Floquet multiplier of the `T`-periodic orbit (`T = 2 pi / w`)
//! passes through `-1`, and a branch of `2T`-periodic orbits bifurcates. On the base
//! frequency `nu = w / 2` a `T`-periodic solution has only even harmonics: harmonic `k` of
//! `w` is harmonic `2k` of `nu` (the load moves the same way), and the harmonic balance on
//! `nu` with `2H` harmonics and `2 Nt` samples holds it exactly ([`lift`]). The generalized
//! Jacobian there couples harmonic `j` only with `j +- 2l` (its switching pattern has period
//! `T`), so it splits into an even and an odd block. The odd block is the harmonic balance
//! of the perturbations `p(t + T) = -p(t)`: it is singular exactly where the multiplier is
//! `-1` (Hill's method), and its kernel is the Floquet vector of that multiplier on the
//! odd harmonics. Near the crossing its smallest singular direction `v` (`odd_kernel`, by
//! inverse iteration) is that vector to within the distance of the point to the crossing.
//!
//! The branch starts at the solutions of `R(X, nu) = 0` with `v . (X - X_T) = eps` (the
//! anchored system, `Anchored`; `w` free): on the `T`-branch `v . (X - X_T)` stays zero
//! (even against odd harmonics), so a solution with `eps != 0` is a `2T`-periodic one. Two
//! amplitudes `eps` and `2 eps` give the branch's direction in `w`; from the first, the
//! sweep's continuation follows it (in `nu`) with the sweep's step
//! rules and bounds. Its points get their stability from the monodromy over `2T`
//! ([`super::branch::branch_stability`] on the model forced on harmonic 2 of `nu`); at
//! the first period doubling of the period-2 branch (the next of a cascade) it is cut and
//! that event reported instead of being followed.

use std::time::Instant;

use faer::{Mat, MatMut};
use semismooth::floquet::BifurcationKind;
use semismooth::linalg::{DenseAssemble, FaerDenseLu};
use semismooth::newton::{NewtonOptions, Tolerances};
use semismooth::polyalgorithm::SmoothingOf;
use semismooth::{
    EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent, Residual,
};

use super::branch::branch_stability;
use super::response::HbTip;
use super::{
    hb_solver, reference_amplitude, ssn_continuation, BifurcationEvent, FrequencyResponse, Setup,
    StateRecovery,
};
use crate::hb::{HbJacobian, SsnHb};
use crate::model::{HarmonicLoad, StructuralModel, Structure};
use crate::settings::{Method, SolverSettings, SweepSettings};
use crate::solve::{hb_options, RunError, HB_OUTPUT_POINTS};

/// The size of the odd-harmonic perturbation of the first point: this fraction of the
/// largest displacement coefficient of the `T`-periodic point (the second point takes
/// twice it). Small enough that the branch is still near its birth, large enough that the
/// anchored system is well conditioned (its Jacobian is singular at `eps = 0`).
const START_AMPLITUDE: f64 = 0.02;

/// Inverse-iteration sweeps for the odd block's kernel.
const INVERSE_ITERATIONS: usize = 4;

/// Period doublings of one sweep that get their period-2 branch (the others are reported
/// only).
pub const MAX_SWITCHES: usize = 4;

/// Why a period-2 branch was not computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PeriodTwoError {
    /// The problem could not be built or the continuation could not run.
    #[error(transparent)]
    Run(#[from] RunError),
    /// Newton on the anchored system (module documentation) did not converge.
    #[error(
        "the period-2 branch did not start: Newton on the anchored system stopped \
         ({termination:?}) after {iterations} iterations at |F| = {residual_norm:.3e}"
    )]
    NotStarted {
        /// Its termination.
        termination: semismooth::newton::Termination,
        /// Its iterations.
        iterations: usize,
        /// Its last `|F|`.
        residual_norm: f64,
    },
}

/// The period-2 branch born at a period doubling ([`period_two_branch`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PeriodTwoBranch {
    /// The period doubling of the `T`-periodic branch it starts from.
    pub from: BifurcationEvent,
    /// The forcing frequency `w` of its first point.
    pub start_omega: f64,
    /// The branch on the base frequency `w / 2`: its points' `omega` are forcing
    /// frequencies `w`; their states are harmonic-balance unknowns on `w / 2` with
    /// `harmonics` (twice the sweep's), and their stability is that of the `2T`-periodic
    /// orbit. Its `events` are those of the period-2 branch, up to the first period
    /// doubling, where it is cut.
    pub response: FrequencyResponse,
    /// The next period doubling of a cascade, where the branch was cut (`None`: none met).
    pub next_event: Option<BifurcationEvent>,
    /// Harmonics of `w / 2` in its states.
    pub harmonics: usize,
    /// The period of its orbits in periods of the forcing (2).
    pub period_multiple: usize,
}

/// What became of the period doubling `from` of a sweep.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum PeriodTwoOutcome {
    /// Its period-2 branch.
    Followed(Box<PeriodTwoBranch>),
    /// No branch: why ([`PeriodTwoError`]'s message).
    NotStarted {
        /// The period doubling.
        from: BifurcationEvent,
        /// Why.
        reason: String,
    },
}

/// The period-2 branches of the first [`MAX_SWITCHES`] period doublings of `response`
/// ([`period_two_branch`]), in branch order.
pub fn period_two_branches(
    structure: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    response: &FrequencyResponse,
) -> Vec<PeriodTwoOutcome> {
    response
        .events
        .iter()
        .filter(|e| e.kind == BifurcationKind::PeriodDoubling)
        .take(MAX_SWITCHES)
        .map(
            |e| match period_two_branch(structure, settings, sweep, response, e) {
                Ok(branch) => PeriodTwoOutcome::Followed(Box::new(branch)),
                Err(err) => PeriodTwoOutcome::NotStarted {
                    from: *e,
                    reason: err.to_string(),
                },
            },
        )
        .collect()
}

/// The period-2 branch of `response` (an SSN-HB sweep of `structure` with `settings` and
/// `sweep`) born at its period doubling `event` (module documentation), followed to the
/// end of the sweep in the direction it leaves the event. `Err` when the method is not
/// SSN-HB or the branch cannot be started.
pub fn period_two_branch(
    structure: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    response: &FrequencyResponse,
    event: &BifurcationEvent,
) -> Result<PeriodTwoBranch, PeriodTwoError> {
    if settings.method != Method::SsnHb || event.kind != BifurcationKind::PeriodDoubling {
        return Err(PeriodTwoError::Run(RunError::Unsupported {
            method: settings.method.name(),
            what: "a period-2 branch (SSN-HB at a period doubling only)",
        }));
    }
    let started = Instant::now();
    let index = nearest_point(response, event);
    let single = response.point_settings(settings, index);
    let doubled = SolverSettings {
        harmonics: 2 * single.harmonics,
        time_samples: 2 * single.time_samples,
        accuracy: None,
        ..single.clone()
    };
    let half = Structure {
        model: on_half_frequency(&structure.model)?,
        omega_1: 0.5 * structure.omega_1,
        observed_dof: structure.observed_dof,
    };
    let point = &response.points[index];
    let nu = 0.5 * point.omega;
    let mut problem = SsnHb::new(&half.model, nu, &hb_options(&doubled)).map_err(RunError::from)?;
    let rows = problem.dim() / (2 * doubled.harmonics + 1);
    let widths = [half.model.dofs(), rows - half.model.dofs()];
    let state = StateRecovery::new(structure, settings, response)
        .state(index)
        .map_err(RunError::from)?;
    let lifted = lift(&state, single.harmonics, &widths);
    let kernel = odd_kernel(&mut problem, &lifted, doubled.harmonics, rows)?;
    let size = lifted[..problem.displacement_len()]
        .iter()
        .fold(0.0f64, |m, u| m.max(u.abs()))
        .max(f64::MIN_POSITIVE);
    // The anchor row reads as a force, like the equations of motion.
    let scale = (0..half.model.dofs())
        .map(|i| crate::model::diagonal_entry(&half.model.stiffness, i).abs())
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let anchor = |eps: f64| Anchor {
        base: &lifted,
        direction: &kernel,
        eps,
        scale,
    };
    let first = anchored_solve(&mut problem, &doubled, anchor(START_AMPLITUDE * size))?;
    let second = anchored_solve(&mut problem, &doubled, anchor(2.0 * START_AMPLITUDE * size))?;
    let (nu_1, nu_2) = (first[first.len() - 1], second[second.len() - 1]);
    let away = if nu_2 != nu_1 {
        nu_2 > nu_1
    } else {
        nu_1 > 0.5 * event.omega
    };
    let (lo, hi) = (
        sweep.omega_ratio_from.min(sweep.omega_ratio_to),
        sweep.omega_ratio_from.max(sweep.omega_ratio_to),
    );
    let from = 2.0 * nu_1 / structure.omega_1;
    if !(lo..=hi).contains(&from) {
        return Err(PeriodTwoError::Run(RunError::InvalidSetting {
            name: "sweep.omega_ratio_to",
            value: from,
            allowed: "a sweep range holding the period-2 branch's first point",
        }));
    }
    let branch_sweep = SweepSettings {
        omega_ratio_from: from,
        omega_ratio_to: if away { hi } else { lo },
        ..sweep.clone()
    };
    let start = first[..first.len() - 1].to_vec();
    let bounds = (0.5 * lo * structure.omega_1, 0.5 * hi * structure.omega_1);
    let mut branch = follow_half(
        &half,
        (&doubled, &branch_sweep, bounds),
        &mut problem,
        start,
        started,
    )?;
    let next_event = cut_at_next_doubling(&half, &doubled, &branch_sweep, &mut branch)?;
    Ok(PeriodTwoBranch {
        from: *event,
        start_omega: 2.0 * nu_1,
        response: on_forcing_frequency(branch, structure.omega_1),
        next_event: next_event.map(|e| doubled_event(&e)),
        harmonics: doubled.harmonics,
        period_multiple: 2,
    })
}

/// The point of `response` nearest to `event`'s frequency among the two it lies between.
fn nearest_point(response: &FrequencyResponse, event: &BifurcationEvent) -> usize {
    let i = event.index.min(response.points.len() - 1);
    let before = i.saturating_sub(1);
    let distance = |j: usize| (response.points[j].omega - event.omega).abs();
    if distance(before) < distance(i) {
        before
    } else {
        i
    }
}

/// `model` with its load on the base frequency `w / 2`: harmonic `k` of `w` becomes
/// harmonic `2k`.
pub fn on_half_frequency(model: &StructuralModel) -> Result<StructuralModel, RunError> {
    let mut half = model.clone();
    let mut load = HarmonicLoad::zero(model.dofs());
    for h in model.load.harmonics() {
        load.add_harmonic(2 * h.harmonic, &h.cosine, &h.sine)?;
    }
    half.load = load;
    Ok(half)
}

/// A `T`-periodic harmonic-balance state (`H` harmonics of `w`, blocks of `widths` rows,
/// each harmonic-major: index `j rows + row`, `j = 0` mean, `2k - 1` cosine, `2k` sine of
/// harmonic `k`) on the base frequency `w / 2` with `2H` harmonics: harmonic `k` moves to
/// `2k`, the odd harmonics are zero.
pub fn lift(x: &[f64], harmonics: usize, widths: &[usize]) -> Vec<f64> {
    let (size, doubled) = (2 * harmonics + 1, 4 * harmonics + 1);
    let mut out = vec![0.0; widths.iter().sum::<usize>() * doubled];
    let (mut from, mut to) = (0, 0);
    for &w in widths {
        for j in 0..size {
            // cos k -> cos 2k (index 4k - 1), sin k -> sin 2k (index 4k).
            let target = if j == 0 {
                0
            } else if j % 2 == 1 {
                2 * j + 1
            } else {
                2 * j
            };
            out[to + target * w..to + (target + 1) * w]
                .copy_from_slice(&x[from + j * w..from + (j + 1) * w]);
        }
        from += w * size;
        to += w * doubled;
    }
    out
}

/// Whether coefficient index `j` (harmonic-major, `0` mean) belongs to an odd harmonic.
fn odd_harmonic(j: usize) -> bool {
    j > 0 && j.div_ceil(2) % 2 == 1
}

/// The unit vector (in the unknowns of `problem`) spanning the near-kernel of the odd
/// harmonics' block of the generalized Jacobian at `x` (module documentation): inverse
/// iteration on the dense odd block, the even unknowns zero.
fn odd_kernel(
    problem: &mut SsnHb,
    x: &[f64],
    harmonics: usize,
    rows: usize,
) -> Result<Vec<f64>, RunError> {
    let mut jac = problem.new_jacobian();
    problem
        .jacobian(x, &mut jac)
        .map_err(|e| RunError::Core(e.into()))?;
    let n = problem.dim();
    let mut full = Mat::<f64>::zeros(n, n);
    jac.assemble_dense(full.as_mut());
    let widths = problem.displacement_len() / (2 * harmonics + 1);
    let blocks = [(0, widths), (problem.displacement_len(), rows - widths)];
    let odd: Vec<usize> = blocks
        .iter()
        .flat_map(|&(offset, w)| {
            (0..2 * harmonics + 1)
                .filter(|&j| odd_harmonic(j))
                .flat_map(move |j| offset + j * w..offset + (j + 1) * w)
        })
        .collect();
    let block = Mat::<f64>::from_fn(odd.len(), odd.len(), |i, j| full[(odd[i], odd[j])]);
    let mut lu = FaerDenseLu::new();
    if lu.factor(&block).is_err() {
        // Exactly singular: a shift of round-off size keeps the direction.
        let shift = 1e-12 * (0..odd.len()).fold(0.0f64, |m, i| m.max(block[(i, i)].abs()));
        let shifted = Mat::<f64>::from_fn(odd.len(), odd.len(), |i, j| {
            block[(i, j)] + if i == j { shift } else { 0.0 }
        });
        lu.factor(&shifted).map_err(|e| RunError::Core(e.into()))?;
    }
    let mut v: Vec<f64> = (0..odd.len()).map(|i| 1.0 + 0.1 * i as f64).collect();
    for _ in 0..INVERSE_ITERATIONS {
        lu.solve_in_place(&mut v)
            .map_err(|e| RunError::Core(e.into()))?;
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        v.iter_mut().for_each(|a| *a /= norm);
    }
    let mut out = vec![0.0; n];
    for (&i, a) in odd.iter().zip(&v) {
        out[i] = *a;
    }
    Ok(out)
}

/// The anchor `v . (X - base) = eps` of the period-2 branch's first points.
#[derive(Clone, Copy)]
struct Anchor<'a> {
    base: &'a [f64],
    /// `v`, zero on the even harmonics.
    direction: &'a [f64],
    eps: f64,
    /// Scale of the anchor row (a stiffness: it reads as a force).
    scale: f64,
}

/// The harmonic balance with its frequency free, anchored by [`Anchor`].
struct Anchored<'a> {
    hb: &'a mut SsnHb,
    anchor: Anchor<'a>,
}

/// The Jacobian of [`Anchored`]: the HB Jacobian bordered by `dR/dnu` and the anchor row.
#[derive(Debug, Clone)]
struct AnchoredJacobian {
    inner: HbJacobian,
    column: Vec<f64>,
    row: Vec<f64>,
}

impl DenseAssemble for AnchoredJacobian {
    fn dim(&self) -> usize {
        self.column.len() + 1
    }

    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        let n = self.column.len();
        out.fill(0.0);
        self.inner
            .assemble_dense(out.as_mut().submatrix_mut(0, 0, n, n));
        for i in 0..n {
            out[(i, n)] = self.column[i];
            out[(n, i)] = self.row[i];
        }
    }
}

impl Residual for Anchored<'_> {
    fn dim(&self) -> usize {
        self.hb.dim() + 1
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let n = self.hb.dim();
        let nu = x[n];
        if !(nu.is_finite() && nu > 0.0) {
            return Err(EvaluationError::OutsideDomain {
                what: "base frequency",
                value: nu,
            });
        }
        self.hb.set_parameter(nu);
        self.hb.residual(&x[..n], &mut out[..n])?;
        let a = self.anchor;
        let along: f64 = (0..n).map(|i| a.direction[i] * (x[i] - a.base[i])).sum();
        out[n] = a.scale * (along - a.eps);
        Ok(())
    }
}

impl GeneralizedJacobian for Anchored<'_> {
    type Jacobian = AnchoredJacobian;

    fn new_jacobian(&self) -> AnchoredJacobian {
        AnchoredJacobian {
            inner: self.hb.new_jacobian(),
            column: vec![0.0; self.hb.dim()],
            row: self
                .anchor
                .direction
                .iter()
                .map(|v| self.anchor.scale * v)
                .collect(),
        }
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut AnchoredJacobian) -> Result<(), EvaluationError> {
        let n = self.hb.dim();
        self.hb.set_parameter(x[n]);
        self.hb.jacobian(&x[..n], &mut jac.inner)?;
        let mut scratch = vec![0.0; n];
        self.hb
            .residual_parameter_derivative(&x[..n], &mut jac.column, &mut scratch)
    }
}

/// The solution `[X; nu]` of the anchored system ([`Anchored`]), from `base + eps v` at the
/// problem's current frequency (restored after).
fn anchored_solve(
    problem: &mut SsnHb,
    settings: &SolverSettings,
    anchor: Anchor<'_>,
) -> Result<Vec<f64>, PeriodTwoError> {
    let nu = problem.parameter();
    let mut x: Vec<f64> = anchor
        .base
        .iter()
        .zip(anchor.direction)
        .map(|(b, v)| b + anchor.eps * v)
        .chain([nu])
        .collect();
    let mut anchored = Anchored {
        hb: problem,
        anchor,
    };
    let options = NewtonOptions {
        tolerances: Tolerances::absolute(settings.tolerance),
        max_iterations: settings.max_iterations,
        ..NewtonOptions::default()
    };
    let report =
        semismooth::newton::solve(&mut anchored, &mut FaerDenseLu::new(), &mut x, &options)
            .map_err(RunError::from)?;
    problem.set_parameter(nu);
    if !report.converged() {
        return Err(PeriodTwoError::NotStarted {
            termination: report.termination.clone(),
            iterations: report.iterations,
            residual_norm: report.residual_norm(),
        });
    }
    Ok(x)
}

/// The sweep's continuation ([`super::follow`]) of `problem` on the half-frequency
/// structure from the solution `start` at `sweep.omega_ratio_from`, within `bounds` (of the
/// base frequency).
fn follow_half(
    half: &Structure,
    (settings, sweep, bounds): (&SolverSettings, &SweepSettings, (f64, f64)),
    problem: &mut SsnHb,
    start: Vec<f64>,
    started: Instant,
) -> Result<FrequencyResponse, RunError> {
    let dofs = half.model.dofs();
    let output_points = HB_OUTPUT_POINTS.max(settings.time_samples);
    let u_ref = reference_amplitude(half);
    let mut tip = HbTip::new(settings.harmonics, output_points, dofs, half.observed_dof)?;
    let mut measure = |_: &SsnHb, x: &[f64], _: f64| tip.extremes(x);
    let method = ssn_continuation(&half.model, problem, u_ref);
    let setup = Setup {
        settings,
        sweep,
        omega_1: half.omega_1,
        u_ref,
        dofs,
        method,
        output_points,
        started,
        start: Some((start, Default::default())),
        bounds: Some(bounds),
        compaction: None,
    };
    super::follow(
        (problem, Some(SmoothingOf::new())),
        &mut *hb_solver(settings.linear_solver),
        setup,
        &mut measure,
        |c| c,
        None,
    )
}

/// Sets the stability of the period-2 branch `branch` (on the half frequency) and cuts it
/// after its first period doubling, which is returned.
fn cut_at_next_doubling(
    half: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    branch: &mut FrequencyResponse,
) -> Result<Option<BifurcationEvent>, RunError> {
    let started = Instant::now();
    let mut stability = branch_stability(half, settings, branch, sweep.stability, None)?;
    let next = stability
        .events
        .iter()
        .find(|e| e.kind == BifurcationKind::PeriodDoubling)
        .copied();
    if let Some(e) = next {
        let keep = e.index + 1;
        branch.points.truncate(keep);
        stability.points.truncate(keep);
        stability.events.retain(|x| x.index < keep);
        let folds: Vec<(usize, f64)> = branch
            .fold_indices
            .iter()
            .zip(&branch.folds)
            .filter(|(i, _)| **i < keep)
            .map(|(i, w)| (*i, *w))
            .collect();
        branch.fold_indices = folds.iter().map(|f| f.0).collect();
        branch.folds = folds.iter().map(|f| f.1).collect();
    }
    branch.set_stability(stability);
    branch.stability_seconds = started.elapsed().as_secs_f64();
    Ok(next)
}

/// `event` of the half-frequency branch with its frequencies in the forcing's.
fn doubled_event(event: &BifurcationEvent) -> BifurcationEvent {
    BifurcationEvent {
        omega: 2.0 * event.omega,
        uncertainty: event.uncertainty.map(|u| 2.0 * u),
        ..*event
    }
}

/// The half-frequency branch with its frequencies in the forcing's (`omega_1` the
/// structure's).
fn on_forcing_frequency(mut branch: FrequencyResponse, omega_1: f64) -> FrequencyResponse {
    branch.omega_1 = omega_1;
    branch.omega_from *= 2.0;
    branch.omega_to *= 2.0;
    for p in &mut branch.points {
        p.omega *= 2.0;
    }
    for w in branch.folds.iter_mut().chain(&mut branch.corner_folds) {
        *w *= 2.0;
    }
    for e in &mut branch.events {
        *e = doubled_event(e);
    }
    branch
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lifting_moves_harmonic_k_to_2k_and_leaves_the_odd_ones_zero() {
        // H = 1, widths [2, 1]: U = [u0 (2), c1 (2), s1 (2)], Lambda = [l0, lc1, ls1].
        let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        let y = lift(&x, 1, &[2, 1]);
        // 2H = 2: blocks 0, c1, s1, c2, s2.
        assert_eq!(
            &y[..10],
            &[1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 3.0, 4.0, 5.0, 6.0]
        );
        assert_eq!(&y[10..], &[7.0, 0.0, 0.0, 8.0, 9.0]);
        let odd: Vec<usize> = (0..5).filter(|&j| odd_harmonic(j)).collect();
        assert_eq!(odd, [1, 2]);
        assert!(odd_harmonic(5) && odd_harmonic(6) && !odd_harmonic(7));
    }
}
