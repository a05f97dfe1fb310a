//! A nonlinear mode's backbone: EPMC followed in its amplitude by the core's continuation.

use semismooth::continuation::{
    Branch, Continuation, ContinuationCounters, ContinuationOptions, ContinuationTermination,
    Direction, RestartPolicy,
};
use semismooth::linalg::FaerDenseLu;
use semismooth::{Factorize, Residual};

use super::{
    AmplitudeMeasure, Epmc, EpmcJacobian, EpmcStructuredSolver, LinearMode, ModesError,
    MAX_DENSE_UNKNOWNS,
};
use crate::hb::{HbError, HbOptions, ResponseSummary};

/// Times per period of the points' summaries (at least `4 H + 4`).
const SUMMARY_POINTS: usize = 1024;
use crate::model::StructuralModel;

/// How [`backbone`] solves the bordered EPMC system at each corrector iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum EpmcSolve {
    /// Dense LU of the whole bordered Jacobian (at most [`MAX_DENSE_UNKNOWNS`] unknowns).
    #[default]
    Dense,
    /// [`EpmcStructuredSolver`] on [`Epmc::deflated`]: one structured factorization of the
    /// inner HB Jacobian per iteration (per-harmonic sparse LU and condensation onto the
    /// contacts), for models of thousands of dofs.
    Structured,
}

/// Corrector iterations allowed per attempted step of a backbone
/// ([`ContinuationOptions::max_corrector_iterations`]): past the onset of contact at a stop
/// the semismooth Newton corrector changes its active set sample by sample and may need
/// more than the core's default 10.
pub const BACKBONE_CORRECTOR_ITERATIONS: usize = 30;

/// The smallest step of a backbone ([`ContinuationOptions::min_step`]), a quarter of the
/// core's default: the corner at the onset of contact is passed with steps that small.
pub const BACKBONE_MIN_STEP: f64 = 5e-4;

/// The continuation a backbone starts from ([`BackboneOptions::continuation`]): the core's
/// defaults, with [`BACKBONE_CORRECTOR_ITERATIONS`] and [`BACKBONE_MIN_STEP`], the step
/// halved from `max_step` down to `min_step` before the run gives up, then the corner
/// passes, restarts ([`RestartPolicy`]) and the exit-tangent pass
/// ([`ContinuationOptions::exit_tangents`]). A mass hitting a rigid stop leaves the linear
/// branch `w = omega_n` at a corner, `w - omega_n` growing like the square root of the
/// amplitude past the onset; a stiff spring in front of the stop rounds it off only a
/// little. Runs whose steps never fail take the same path as with the core's defaults.
pub fn backbone_continuation() -> ContinuationOptions {
    let defaults = ContinuationOptions::default();
    // Halving from max_step down to min_step, plus one attempt at min_step.
    let halvings = (defaults.max_step / BACKBONE_MIN_STEP).log2().ceil() as usize + 2;
    ContinuationOptions {
        min_step: BACKBONE_MIN_STEP,
        max_corrector_iterations: BACKBONE_CORRECTOR_ITERATIONS,
        max_consecutive_failures: halvings.max(defaults.max_consecutive_failures),
        restarts: Some(RestartPolicy::default()),
        exit_tangents: true,
        ..defaults
    }
}

/// Default of [`BackboneOptions::relative_tolerance`].
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-12;

/// What [`backbone`] computes.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BackboneOptions {
    /// The harmonic balance (`H`, `Nt`, `c`).
    pub hb: HbOptions,
    /// Which linear mode to start from (1: the lowest).
    pub mode: usize,
    /// What the amplitude measures.
    pub measure: AmplitudeMeasure,
    /// The amplitude of the first point (small: the linear mode).
    pub amplitude_from: f64,
    /// The amplitude where the backbone ends.
    pub amplitude_to: f64,
    /// With [`BackboneOptions::by_energy`]: the energy range `(from, to)` ([`Epmc::energy`])
    /// in place of the amplitude range. The first point is the linear mode of energy
    /// `from`; the backbone ends at the first point whose energy reaches `to` (the
    /// amplitude range is then only a safety bound: from the first point to twice the
    /// linear mode's amplitude at energy `to`, since a stop stiffens the mode).
    pub energy_range: Option<(f64, f64)>,
    /// How each corrector iteration is solved. Default [`EpmcSolve::Dense`].
    pub solve: EpmcSolve,
    /// The corrector's tolerance relative to the size of the forces
    /// ([`Epmc::force_scale`] at the largest amplitude of the range): it replaces the
    /// continuation's absolute `corrector_tolerance`, so that a model in other units
    /// (SI: stiffness 1e9, amplitudes 1e-6) follows the same backbone as its
    /// nondimensional twin. `None` keeps the absolute one. Default
    /// `Some(`[`DEFAULT_RELATIVE_TOLERANCE`]`)`.
    pub relative_tolerance: Option<f64>,
    /// The continuation (its parameter bounds are set from the amplitude range; without a
    /// `state_scale` one is made from the amplitude range, `omega_n` and the stiffness).
    /// Default [`backbone_continuation`].
    pub continuation: ContinuationOptions,
}

impl BackboneOptions {
    /// Mode `mode` from `amplitude_from` to `amplitude_to` with the default HB and
    /// continuation.
    pub fn new(
        mode: usize,
        measure: AmplitudeMeasure,
        amplitude_from: f64,
        amplitude_to: f64,
    ) -> Self {
        Self {
            hb: HbOptions::default(),
            mode,
            measure,
            amplitude_from,
            amplitude_to,
            energy_range: None,
            solve: EpmcSolve::Dense,
            relative_tolerance: Some(DEFAULT_RELATIVE_TOLERANCE),
            continuation: backbone_continuation(),
        }
    }

    /// Mode `mode` from the energy `energy_from` to `energy_to` (the period mean of the
    /// mechanical energy, the natural measure of a conservative system's backbone).
    pub fn by_energy(
        mode: usize,
        measure: AmplitudeMeasure,
        energy_from: f64,
        energy_to: f64,
    ) -> Self {
        Self {
            energy_range: Some((energy_from, energy_to)),
            ..Self::new(mode, measure, f64::NAN, f64::NAN)
        }
    }
}

/// The amplitude range of `options`: as given, or from its energy range on the linear
/// mode of `epmc` (whose energy is quadratic in the amplitude).
fn amplitude_range(epmc: &Epmc, options: &BackboneOptions) -> Result<(f64, f64), ModesError> {
    let Some((from, to)) = options.energy_range else {
        return Ok((options.amplitude_from, options.amplitude_to));
    };
    semismooth::InvalidOption::check(
        from.is_finite() && to.is_finite() && from > 0.0 && to > from,
        "energy range",
        to,
        "two positive energies, increasing",
    )
    .map_err(|e| ModesError::Hb(e.into()))?;
    let unit = epmc.energy(&epmc.linear_start(1.0));
    Ok(((from / unit).sqrt(), 2.0 * (to / unit).sqrt()))
}

/// One point of a backbone.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BackbonePoint {
    /// The amplitude (the continuation parameter, [`AmplitudeMeasure`]).
    pub amplitude: f64,
    /// The frequency `w` of the periodic motion.
    pub omega: f64,
    /// The modal damping `xi` (the term `-xi M u'`).
    pub modal_damping: f64,
    /// NLvib's damping ratio `xi / (2 w)`.
    pub damping_ratio: f64,
    /// The period mean of the mechanical energy ([`Epmc::energy`]).
    pub energy: f64,
    /// Extremes of the summary dof ([`Backbone::summary_dof`]), penetration and mean
    /// contact forces over the period.
    pub summary: ResponseSummary,
    /// The EPMC unknowns `[U; Lambda; w; xi]`.
    pub unknowns: Vec<f64>,
}

/// A backbone: its points in the order of the branch, the folds of the amplitude, why it
/// ended, the work.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Backbone {
    /// The linear mode it starts from.
    pub linear: LinearMode,
    /// The points, the first corrected at `amplitude_from`.
    pub points: Vec<BackbonePoint>,
    /// The dof of the points' summaries: the measured dof, or the largest entry of the
    /// mode's shape.
    pub summary_dof: usize,
    /// Amplitudes where the branch turns back.
    pub folds: Vec<f64>,
    /// Why the continuation ended.
    pub termination: ContinuationTermination,
    /// The continuation's work counters.
    pub counters: ContinuationCounters,
    /// How the bordered system was solved (the options' [`EpmcSolve`]).
    pub solve: EpmcSolve,
}

/// The backbone of `model`'s mode `options.mode` ([`Epmc`]): from its linear mode at
/// `amplitude_from` to `amplitude_to`, by pseudo-arclength continuation of the bordered EPMC
/// system ([`EpmcSolve`]: dense LU of the whole bordered Jacobian, at most
/// [`MAX_DENSE_UNKNOWNS`] unknowns, or the structured solve). `Err` only when it cannot
/// start.
pub fn backbone(
    model: &StructuralModel,
    options: &BackboneOptions,
) -> Result<Backbone, ModesError> {
    // Checked before the (dense) linear mode is computed.
    let rows = model.dofs() + model.contact_count() + model.friction_count();
    let unknowns = rows.saturating_mul(2 * options.hb.harmonics + 1) + 2;
    if options.solve == EpmcSolve::Dense && unknowns > MAX_DENSE_UNKNOWNS {
        return Err(ModesError::TooLarge {
            unknowns,
            limit: MAX_DENSE_UNKNOWNS,
        });
    }
    let mut epmc = match options.solve {
        EpmcSolve::Dense => Epmc::new(model, &options.hb, options.mode, options.measure)?,
        EpmcSolve::Structured => Epmc::deflated(model, &options.hb, options.mode, options.measure)?,
    };
    let (from, to) = amplitude_range(&epmc, options)?;
    semismooth::InvalidOption::check(
        from.is_finite() && to.is_finite() && from > 0.0 && to > 0.0 && from != to,
        "amplitude range",
        to,
        "two different positive amplitudes",
    )
    .map_err(|e| ModesError::Hb(e.into()))?;
    let x0 = epmc.linear_start(from);
    let continuation = continuation_options(&epmc, options, from, to)?;
    let linear = epmc.linear_mode().clone();
    let energy_to = options.energy_range.map(|(_, to)| to);
    let start = (x0.as_slice(), from);
    let branch = match options.solve {
        // The dense fallback of the continuation's own border is affordable here.
        EpmcSolve::Dense => {
            let solver = &mut FaerDenseLu::new();
            follow(&mut epmc, solver, start, continuation, energy_to, true)?
        }
        EpmcSolve::Structured => {
            let solver = &mut EpmcStructuredSolver::new();
            follow(&mut epmc, solver, start, continuation, energy_to, false)?
        }
    };
    let summary_dof = match options.measure {
        AmplitudeMeasure::Dof(dof) => dof,
        _ => (0..linear.shape.len())
            .max_by(|&i, &j| linear.shape[i].abs().total_cmp(&linear.shape[j].abs()))
            .unwrap_or(0),
    };
    let len = epmc.hb_len();
    let times = SUMMARY_POINTS.max(4 * options.hb.harmonics + 4);
    let points = branch
        .points
        .iter()
        .map(|p| {
            Ok(BackbonePoint {
                amplitude: p.parameter,
                omega: epmc.omega(&p.state),
                modal_damping: epmc.modal_damping(&p.state),
                damping_ratio: epmc.damping_ratio(&p.state),
                energy: epmc.energy(&p.state),
                summary: epmc.hb().summary(&p.state[..len], summary_dof, times)?,
                unknowns: p.state.clone(),
            })
        })
        .collect::<Result<_, HbError>>()?;
    Ok(Backbone {
        linear,
        summary_dof,
        folds: branch.fold_parameters(),
        points,
        termination: branch.termination,
        counters: branch.counters,
        solve: options.solve,
    })
}

/// The continuation options of `options` for the amplitude range `from`..`to`: its bounds,
/// direction and scales, and the corrector's tolerance from the relative one.
fn continuation_options(
    epmc: &Epmc,
    options: &BackboneOptions,
    from: f64,
    to: f64,
) -> Result<ContinuationOptions, ModesError> {
    let mut continuation = options.continuation.clone();
    continuation.parameter_min = from.min(to);
    continuation.parameter_max = from.max(to);
    continuation.direction = if to > from {
        Direction::Increasing
    } else {
        Direction::Decreasing
    };
    continuation.parameter_scale = (to - from).abs();
    if continuation.state_scale.is_none() {
        continuation.state_scale = Some(state_scale(epmc, from.abs().max(to.abs())));
    }
    if let Some(relative) = options.relative_tolerance {
        semismooth::InvalidOption::check(
            relative.is_finite() && relative > 0.0,
            "relative tolerance",
            relative,
            "a positive number",
        )
        .map_err(|e| ModesError::Hb(e.into()))?;
        continuation.corrector_tolerance = relative * epmc.force_scale(from.abs().max(to.abs()));
    }
    Ok(continuation)
}

/// The branch of `epmc` from `(x0, amplitude)` with `solver`, up to the energy `energy_to`
/// if any ([`up_to_energy`]); `dense_fallback`: the continuation may factor its bordered
/// matrix densely when `solver` fails.
fn follow<S: Factorize<EpmcJacobian>>(
    epmc: &mut Epmc,
    solver: &mut S,
    (x0, from): (&[f64], f64),
    options: ContinuationOptions,
    energy_to: Option<f64>,
    dense_fallback: bool,
) -> Result<Branch, ModesError> {
    let mut continuation = Continuation::new(epmc, solver, x0, from, options)
        .map_err(|e| ModesError::Continuation(e.to_string()))?;
    if dense_fallback {
        continuation = continuation.with_dense_fallback();
    }
    Ok(match energy_to {
        Some(energy_to) => up_to_energy(continuation, energy_to),
        None => continuation.run(),
    })
}

/// The branch of `continuation` up to its first point whose energy reaches `energy_to`
/// (then ended as at a bound: `ReachedBound` with the energies).
fn up_to_energy<S: Factorize<EpmcJacobian>>(
    mut continuation: Continuation<'_, Epmc, S>,
    energy_to: f64,
) -> Branch {
    let mut points = Vec::new();
    let mut reached = None;
    while let Some(point) = continuation.next() {
        let energy = continuation.problem().energy(&point.state);
        points.push(point);
        if energy >= energy_to {
            reached = Some(energy);
            break;
        }
    }
    let termination = match reached {
        Some(parameter) => ContinuationTermination::ReachedBound {
            parameter,
            bound: energy_to,
        },
        None => continuation
            .termination()
            .cloned()
            .unwrap_or(ContinuationTermination::MaxPoints {
                points: points.len(),
            }),
    };
    Branch {
        points,
        events: continuation.events().to_vec(),
        termination,
        counters: continuation.counters(),
    }
}

/// Typical sizes of the EPMC unknowns: `amplitude` for the displacements, the stiffness
/// scale times it for the forces, `omega_n` for `w` and `xi`.
fn state_scale(epmc: &Epmc, amplitude: f64) -> Vec<f64> {
    let displacements = epmc.hb().displacement_len();
    let len = epmc.hb_len();
    let omega = epmc.linear_mode().omega;
    let mut scale = vec![amplitude; epmc.dim()];
    scale[displacements..len].fill(epmc.row_scale * amplitude);
    scale[len] = omega;
    scale[len + 1] = omega;
    scale
}
