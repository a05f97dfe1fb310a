//! Time-marching reference: march `M u'' + D u' + K u = f(t) + G^T lambda` from a given
//! state with a contact-aware one-step scheme until the response is periodic, then report
//! one steady period.
//!
//! # Schemes
//!
//! Two schemes that never let the contacts penetrate at the step level (each step's contact
//! problem is a small linear complementarity problem solved by the core's
//! [`Lemke`](semismooth::lemke::Lemke)):
//!
//! - [`MarchScheme::MasslessContactTrapezoidal`] for the *modified* mass (every contact dof
//!   has a zero mass row). Trapezoidal rule (Newmark average acceleration,
//!   `beta = 1/4, gamma = 1/2`), second order and energy conserving for the linear part,
//!   with the contact imposed on the *positions* at `t_{n+1}`:
//!   `K_eff u_{n+1} = b_n + f_{n+1} + G^T lambda_{n+1}`, `K_eff = K + (2/h) D + (4/h^2) M`,
//!   `b_n = M ((4/h^2) u_n + (4/h) v_n) + D ((2/h) u_n + v_n) + r_n`, where `r_n = M a_n` is
//!   the inertial force. Writing `u_{n+1} = u_free + Y lambda`, `Y = K_eff^{-1} G^T`, the
//!   step is the static LCP `w = q + W z`, `z = -lambda >= 0`, `w = g - G u_{n+1} >= 0`,
//!   `q = g - G u_free`, `W = G Y` (`Y` and `W` computed once, `m` solves). Then
//!   `v_{n+1} = (2/h)(u_{n+1} - u_n) - v_n` (the trapezoidal relation, no acceleration
//!   needed) and `r_{n+1} = f_{n+1} + G^T lambda_{n+1} - D v_{n+1} - K u_{n+1}`.
//!
//!   *Massless dofs.* Only `r = M a` enters the update, never `a` itself, so the undefined
//!   acceleration of a massless dof is never needed: on a zero mass row `r = 0` and the
//!   step solves that row's equilibrium `K u_{n+1} + D v_{n+1} = f_{n+1} + G^T lambda_{n+1}`
//!   exactly (with the trapezoidal velocity). The initial `r_0` comes from the equation
//!   of motion at `t_0` on the massive rows and is set to 0 on the massless rows; the
//!   massless rows of `r` are reset to exactly 0 after each step (they are zero up to
//!   round-off). An initial state that violates a massless row's equilibrium is
//!   projected onto it by the first step.
//!
//!   *Energy.* With `E = v^T M v / 2 + u^T K u / 2`, the scheme satisfies exactly (to
//!   round-off) `E_{n+1} - E_n = (u_{n+1} - u_n)^T (f_n + f_{n+1} + G^T (lambda_n +
//!   lambda_{n+1})) / 2 - (h/4)(v_n + v_{n+1})^T D (v_n + v_{n+1})`. Without force and
//!   damping the energy is therefore constant while the contacts stay open or stay
//!   closed (then `G (u_{n+1} - u_n) = 0`); a step on which a contact closes or opens
//!   changes it by `-(lambda_n . w_{n+1} - lambda_{n+1} . w_n) / 2`, a product of an
//!   `O(h)` force and an `O(h)` gap, i.e. `O(h^2)`, of both signs (closing removes energy,
//!   opening restores it): the energy does not drift but is conserved to round-off only
//!   between contact transitions.
//!
//! - [`MarchScheme::MoreauJean`] for a massive contact dof (consistent or lumped mass):
//!   Moreau–Jean's theta-scheme on velocities with impulses,
//!   `M (v_{n+1} - v_n) + h D v_{n+theta} + h K u_{n+theta} = h f_{n+theta} + G^T P_{n+1}`,
//!   `u_{n+1} = u_n + h v_{n+theta}` (`x_{n+theta} = theta x_{n+1} + (1 - theta) x_n`),
//!   i.e. `M_hat v_{n+1} = M v_n - h D (1 - theta) v_n - h K (u_n + h theta (1 - theta) v_n)
//!   + h f_{n+theta} + G^T P` with `M_hat = M + h theta D + h^2 theta^2 K` factored once.
//!   A contact is active when its predicted gap `g - G (u_n + (h/2) v_n)` is closed
//!   (`<= 0`); on the active set `A` Newton's impact law at velocity level,
//!   `w = -G_A (v_{n+1} + e v_n) >= 0`, `z = -P_A >= 0`, `w . z = 0`, is the LCP
//!   `w = q + W_AA z` with `q = -G_A (v_free + e v_n)`, `W = G M_hat^{-1} G^T`.
//!   The reported contact force is `P / h`. The answer depends on the restitution `e`
//!   (the semi-discrete problem with a massive contact node needs an impact law), and the
//!   scheme is first order in time for the positions near impacts (an impact is resolved
//!   within one step; positions may penetrate by `O(h)` on the steps where a contact is
//!   active), second order (for `theta = 1/2`) in smooth free flight.
//!
//! [`MarchScheme::Auto`] picks the trapezoidal scheme when every contact dof has a zero
//! mass row (and when there is no contact at all), Moreau–Jean otherwise.
//!
//! # Steady state
//!
//! The forcing is `f(t) = load cos(omega t)` (the model's load, `omega` an argument of the
//! march), `T = 2 pi / omega`, `h = T / steps_per_period`; the march starts at `t = 0` (the forcing's cosine peak), so every
//! period starts at a multiple of `T` and the reported period has the same phase as a
//! harmonic-balance solution. After each period the relative period-to-period change is
//! the larger of (a) the change of the full state `(u, v / omega)` sampled at the period
//! start and (b) the change of the observed displacements over the whole period, each
//! relative to the current period's largest absolute value. The march stops when it is
//! below [`MarchOptions::tolerance`]. The change measures the decay of the transient, not
//! the error: with a slowest decay factor `rho` per period the remaining error is about
//! `change * rho / (1 - rho)` (for the canonical rod, `zeta = 0.01`, `rho` is about
//! `exp(-2 pi zeta) = 0.94`, i.e. an error about 16 times the change).
//!
//! # What to expect (measured on the canonical rod)
//!
//! - Modified mass (trapezoidal): steady after 79 periods at tolerance 1e-8 from rest at
//!   2000 steps per period (`docs/performance.md` for the time it takes). The tip touches the gap exactly
//!   (`tip max = 0.5`), the tip minimum is -0.5231507 (it varies by 2e-7 over 1000..8000
//!   steps per period, without a clean order: contact onsets are quantised by the step),
//!   the mean contact force -9.24379e-3 converges at order 2.2. SSN-HB with `H = 40`
//!   agrees with it to 1.3e-5 (tip minimum), 1.1e-4 (tip RMS) and 5.8e-4 (mean contact
//!   force), relative.
//! - Consistent mass (Moreau–Jean): the restitution changes the contact history (one
//!   contact episode per period for `e = 0`, about five bounces for `e = 0.5`, 13 % less
//!   time in contact) but the tip minimum only by ~1e-4 relative. The discrete map need
//!   not lock onto the forcing period: `e = 0` is exactly periodic at 1000 steps per period
//!   but jitters by 5e-4 to 1e-3 (relative, in the tip minimum) between periods at 2000 and
//!   4000, and `e = 0.5` jitters at every step count tried (`O(h)`), so
//!   [`march_to_steady_state`] can end with [`MarchError::NotSteady`], which still carries
//!   the last period. Against SSN-HB (`H = 40`) the mean contact force differs by 1.2 to
//!   1.3 % and the tip minimum by 0.6e-3 to 2e-3: harmonic balance imposes no impact law,
//!   so it cannot be expected to converge to a Moreau–Jean answer here.
//!
//! # Options (defaults)
//! - `steps_per_period`: 2000, `max_periods`: 2000, `tolerance`: 1e-8,
//!   `scheme`: [`MarchScheme::Auto`] (`MoreauJean { theta: 0.5, restitution: 0.0 }` when
//!   chosen by `Auto`).
//!
//! # References
//! - M. Jean, *The non-smooth contact dynamics method*, CMAME 177 (1999) 235–257;
//!   V. Acary, B. Brogliato, *Numerical Methods for Nonsmooth Dynamical Systems*,
//!   Springer 2008, ch. 10 (Moreau–Jean).
//! - H. B. Khenous, P. Laborde, Y. Renard, *Mass redistribution method for finite element
//!   contact problems in elastodynamics*, Eur. J. Mech. A/Solids 27 (2008) 918–932
//!   (massless contact nodes).
//!
//! ```
//! use semismooth_contact::march::{march_to_steady_state, MarchOptions};
//! use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
//! let rod = build_rod(&RodSpec { mass: MassModel::Modified, ..RodSpec::canonical() }).unwrap();
//! let options = MarchOptions { steps_per_period: 200, tolerance: 1e-6, ..MarchOptions::default() };
//! let period = march_to_steady_state(&rod.model, rod.omega(), &options, &[rod.tip_dof()]).unwrap();
//! assert_eq!(period.omega, rod.omega());
//! let tip = &period.displacements[0];
//! assert!(tip.iter().all(|u| *u <= 0.5 + 1e-12)); // never beyond the gap
//! assert!(period.contact_forces[0].iter().all(|l| *l <= 0.0));
//! ```

mod friction;
mod load;
mod step;

pub use step::TimeMarcher;

use semismooth::lemke::LemkeError;
use semismooth::linalg::LinearSolveError;
use semismooth::InvalidOption;

use crate::model::{InvalidModel, SparseMatrix, StructuralModel};

/// The one-step scheme used to march.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum MarchScheme {
    /// [`MarchScheme::MasslessContactTrapezoidal`] when every contact dof has a zero mass
    /// row (or there is no contact) and there is no friction point, otherwise
    /// `MoreauJean { theta: 0.5, restitution: 0.0 }` (`theta = 1` with friction and a contact
    /// row with a massless dof: [`resolve_scheme`]).
    #[default]
    Auto,
    /// Moreau–Jean theta-scheme with impulses and Newton's impact law (first order in time
    /// near impacts).
    MoreauJean {
        /// Implicitness `theta`, in `[0.5, 1]` (0.5: no numerical dissipation in free flight).
        theta: f64,
        /// Newton restitution coefficient `e`, in `[0, 1]` (0: plastic impact).
        restitution: f64,
    },
    /// Trapezoidal rule with the contact imposed on the positions at the end of each step;
    /// requires every contact dof to be massless (zero mass row).
    MasslessContactTrapezoidal,
}

impl MarchScheme {
    /// `MoreauJean { theta: 0.5, restitution: 0.0 }`.
    pub const MOREAU_JEAN_DEFAULT: MarchScheme = MarchScheme::MoreauJean {
        theta: 0.5,
        restitution: 0.0,
    };
}

/// Options of the time-marching reference (see the module docs for defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarchOptions {
    /// Time steps per forcing period (`h = T / steps_per_period`), in `4..=100_000_000`.
    pub steps_per_period: usize,
    /// Periods marched at most before giving up with [`MarchError::NotSteady`], `>= 1`.
    pub max_periods: usize,
    /// Relative period-to-period change below which the response is steady, in `(0, 1)`.
    pub tolerance: f64,
    /// The scheme.
    pub scheme: MarchScheme,
}

impl Default for MarchOptions {
    fn default() -> Self {
        Self {
            steps_per_period: 2000,
            max_periods: 2000,
            tolerance: 1e-8,
            scheme: MarchScheme::Auto,
        }
    }
}

/// Largest accepted `steps_per_period`.
pub const MAX_STEPS_PER_PERIOD: usize = 100_000_000;

impl MarchOptions {
    /// Checks every field; the error names the field, the value and what is allowed.
    pub fn validate(&self) -> Result<(), MarchError> {
        if !(4..=MAX_STEPS_PER_PERIOD).contains(&self.steps_per_period) {
            return Err(MarchError::InvalidOption(InvalidOption {
                name: "steps_per_period",
                value: self.steps_per_period as f64,
                allowed: "an integer in 4..=100000000",
            }));
        }
        if self.max_periods == 0 {
            return Err(MarchError::InvalidOption(InvalidOption::new(
                "max_periods",
                0.0,
                "an integer >= 1",
            )));
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(MarchError::InvalidOption(InvalidOption::new(
                "tolerance",
                self.tolerance,
                "a number in (0, 1)",
            )));
        }
        if let MarchScheme::MoreauJean { theta, restitution } = self.scheme {
            if !(0.5..=1.0).contains(&theta) {
                return Err(MarchError::InvalidOption(InvalidOption::new(
                    "theta",
                    theta,
                    "a number in [0.5, 1]",
                )));
            }
            if !(0.0..=1.0).contains(&restitution) {
                return Err(MarchError::InvalidOption(InvalidOption::new(
                    "restitution",
                    restitution,
                    "a number in [0, 1]",
                )));
            }
        }
        Ok(())
    }
}

/// A full state of the semi-discrete model at a time that is a multiple of the period.
#[derive(Debug, Clone, PartialEq)]
pub struct MarchState {
    /// Displacements `u` (length `N`).
    pub displacement: Vec<f64>,
    /// Velocities `v` (length `N`).
    pub velocity: Vec<f64>,
    /// Contact forces `lambda` (length `m`, `<= 0`); used by the trapezoidal scheme to
    /// form the initial inertial force, ignored by Moreau–Jean.
    pub contact_force: Vec<f64>,
}

impl MarchState {
    /// Checks that the state has `n` displacements and velocities and `m` contact forces,
    /// all finite.
    pub(crate) fn check(&self, n: usize, m: usize) -> Result<(), MarchError> {
        for (what, vec, len) in [
            ("displacement", &self.displacement, n),
            ("velocity", &self.velocity, n),
            ("contact_force", &self.contact_force, m),
        ] {
            if vec.len() != len {
                return Err(MarchError::StateDimension {
                    what,
                    expected: len,
                    found: vec.len(),
                });
            }
            if let Some((index, value)) = vec.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(MarchError::NonFiniteState {
                    what,
                    index,
                    value: *value,
                });
            }
        }
        Ok(())
    }

    /// The state at rest: `u = v = 0`, `lambda = 0`.
    pub fn rest(model: &StructuralModel) -> Self {
        Self {
            displacement: vec![0.0; model.dofs()],
            velocity: vec![0.0; model.dofs()],
            contact_force: vec![0.0; model.contact_count()],
        }
    }
}

/// Work done by a march.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MarchCounters {
    /// Time steps taken.
    pub steps: u64,
    /// Sparse numeric factorizations (1 per march).
    pub factorizations: u64,
    /// Sparse triangular solves (one per step plus `m + 1` at set-up).
    pub linear_solves: u64,
    /// LCPs handed to Lemke's method (steps on which some contact was closed or active).
    pub contact_solves: u64,
    /// Steps on which some contact force (or impulse) was non-zero.
    pub active_steps: u64,
    /// Pivots made by Lemke's method over all contact solves.
    pub lemke_pivots: u64,
}

/// One steady period of the marched response.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyPeriod {
    /// The scheme used (never [`MarchScheme::Auto`]).
    pub scheme: MarchScheme,
    /// Forcing angular frequency `omega`.
    pub omega: f64,
    /// `steps_per_period + 1` times `j T / steps_per_period`, `j = 0..=steps_per_period`,
    /// measured from the start of the reported period (a multiple of `T`, so `t = 0` is
    /// the forcing's cosine peak, the phase of harmonic balance).
    pub times: Vec<f64>,
    /// The dofs observed, in the order given.
    pub observed_dofs: Vec<usize>,
    /// One series per observed dof, at [`SteadyPeriod::times`].
    pub displacements: Vec<Vec<f64>>,
    /// One series per contact, at [`SteadyPeriod::times`]: the force `lambda <= 0` of the
    /// step (impulse / h for Moreau–Jean).
    pub contact_forces: Vec<Vec<f64>>,
    /// One series per friction point, at [`SteadyPeriod::times`]: its tangential force
    /// (impulse / h).
    pub friction_forces: Vec<Vec<f64>>,
    /// One series per friction point, at [`SteadyPeriod::times`]: its slip velocity
    /// `g_t . v` at the end of the step.
    pub slip_velocities: Vec<Vec<f64>>,
    /// One series per row of the 3-D frictional contacts (per contact its normal force
    /// `<= 0` when unilateral, then its two tangential forces), at
    /// [`SteadyPeriod::times`] (impulse / h).
    pub frictional_forces: Vec<Vec<f64>>,
    /// Two series per 3-D frictional contact, at [`SteadyPeriod::times`]: its slip
    /// velocity `g_a . v` minus the obstacle's sliding velocity, `a = 1, 2`.
    pub frictional_slip_velocities: Vec<Vec<f64>>,
    /// Periods marched, the reported one included.
    pub periods: usize,
    /// Relative period-to-period change of the last period (below the tolerance).
    pub period_change: f64,
    /// Work counters over the whole march.
    pub counters: MarchCounters,
    /// The state at the end of the reported period (a multiple of `T`): pass it to
    /// [`march_from_state`] to warm start another march.
    pub final_state: MarchState,
}

/// Why a march could not be carried out or did not become periodic.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MarchError {
    /// An option is outside its allowed range.
    #[error("invalid option {0}")]
    InvalidOption(#[from] InvalidOption),
    /// The model is not usable (sizes, non-finite data, frequency, contacts).
    #[error(transparent)]
    Model(#[from] InvalidModel),
    /// A vector of the initial state has the wrong length.
    #[error("initial state {what} has length {found}, expected {expected}")]
    StateDimension {
        /// Which vector.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// An entry of the initial state is not finite.
    #[error("initial state {what}[{index}] is not finite ({value})")]
    NonFiniteState {
        /// Which vector.
        what: &'static str,
        /// Index of the entry.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The trapezoidal scheme was requested but a contact dof carries mass.
    #[error(
        "the massless-contact trapezoidal scheme needs massless contact dofs: dof {dof} has a \
         mass row with largest entry {mass:e} (use MoreauJean or a modified mass)"
    )]
    MassiveContactDof {
        /// The contact dof.
        dof: usize,
        /// Largest absolute entry of its mass row.
        mass: f64,
    },
    /// The iteration matrix could not be factored.
    #[error("factorization of {matrix} failed: {source}")]
    Factorization {
        /// `"K_eff"` or `"M_hat"`.
        matrix: &'static str,
        /// What went wrong.
        source: LinearSolveError,
    },
    /// Lemke's method could not run or did not solve a step's contact LCP.
    #[error("contact LCP at period {period}, step {step} not solved: {source}")]
    ContactSolve {
        /// Period (1-based).
        period: usize,
        /// Step within the period (1-based).
        step: usize,
        /// Lemke's error.
        source: LemkeError,
    },
    /// The semismooth Newton of a step's contact and friction problem did not converge.
    #[error(
        "contact and friction problem at period {period}, step {step} not solved: residual \
         {residual:e} above the tolerance {tolerance:e}"
    )]
    FrictionSolve {
        /// Period (1-based).
        period: usize,
        /// Step within the period (1-based).
        step: usize,
        /// `|F|_2` reached.
        residual: f64,
        /// The tolerance asked.
        tolerance: f64,
    },
    /// A non-finite value appeared in the state.
    #[error("non-finite state at period {period}, step {step}")]
    NonFinite {
        /// Period (1-based).
        period: usize,
        /// Step within the period (1-based).
        step: usize,
    },
    /// `max_periods` periods were marched without reaching the tolerance. The last period
    /// is returned all the same (its `period_change` is `change`): Moreau–Jean with
    /// impacts may settle on an invariant set that jitters by `O(h)` from period to period
    /// instead of an exactly periodic orbit (see the module docs).
    #[error("not steady after {periods} periods: relative period-to-period change {change:e}")]
    NotSteady {
        /// Periods marched.
        periods: usize,
        /// Last relative change.
        change: f64,
        /// The last period marched.
        last_period: Box<SteadyPeriod>,
    },
}

/// Largest absolute entry of column `j` (= row `j`, `M` is symmetric).
pub(crate) fn column_max_abs(m: &SparseMatrix, j: usize) -> f64 {
    m.as_ref()
        .val_of_col(j)
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()))
}

/// The scheme `Auto` resolves to for this model: with friction points Moreau–Jean (the
/// trapezoidal scheme imposes positions, Coulomb's law acts on velocities), with
/// `theta = 1` when a contact's row has a massless dof (which then follows its
/// quasi-static equilibrium at each step; `theta = 1/2` alternates about it), else
/// `theta = 1/2` (no numerical damping: `theta = 1` damps a resonance by about `pi /
/// steps` of critical).
pub fn resolve_scheme(model: &StructuralModel, scheme: MarchScheme) -> MarchScheme {
    let massless = |dof: &usize| column_max_abs(&model.mass, *dof) == 0.0;
    match scheme {
        MarchScheme::Auto if model.has_friction() => {
            let normal_rows = model
                .frictional_contacts
                .iter()
                .filter_map(|p| p.normal_row());
            if (model.contacts.iter().map(|c| &c.row))
                .chain(normal_rows)
                .flat_map(|row| row.dofs())
                .any(massless)
            {
                MarchScheme::MoreauJean {
                    theta: 1.0,
                    restitution: 0.0,
                }
            } else {
                MarchScheme::MOREAU_JEAN_DEFAULT
            }
        }
        MarchScheme::Auto => {
            if model.rows().flat_map(|row| row.dofs()).all(massless) {
                MarchScheme::MasslessContactTrapezoidal
            } else {
                MarchScheme::MOREAU_JEAN_DEFAULT
            }
        }
        other => other,
    }
}

/// Largest absolute value of a slice (0 for an empty one).
fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
}

/// Relative change `max |a - b| / max |a|` (0 when both are zero).
fn relative_change(a: &[f64], b: &[f64]) -> f64 {
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    let scale = max_abs(a);
    if diff == 0.0 {
        0.0
    } else if scale > 0.0 {
        diff / scale
    } else {
        f64::INFINITY
    }
}

/// Marches `model` forced at `omega` (finite, `> 0`) from rest until the period-to-period
/// change is below the tolerance and returns the last period (see the module docs).
pub fn march_to_steady_state(
    model: &StructuralModel,
    omega: f64,
    options: &MarchOptions,
    observed_dofs: &[usize],
) -> Result<SteadyPeriod, MarchError> {
    march_from_state(
        model,
        omega,
        options,
        observed_dofs,
        &MarchState::rest(model),
    )
}

/// Like [`march_to_steady_state`] but from a given state at `t = 0` (a warm start, e.g.
/// [`SteadyPeriod::final_state`] of a previous march).
pub fn march_from_state(
    model: &StructuralModel,
    omega: f64,
    options: &MarchOptions,
    observed_dofs: &[usize],
    initial: &MarchState,
) -> Result<SteadyPeriod, MarchError> {
    let mut marcher = TimeMarcher::new(model, omega, options, initial)?;
    let n = model.dofs();
    let m = model.contact_count();
    model.check_observed(observed_dofs)?;
    let spp = options.steps_per_period;
    let samples = spp + 1;
    let nobs = observed_dofs.len();
    // Observed series of the current and previous periods, sample-major, and the
    // contact forces of the current period.
    let mut series = vec![0.0; nobs * samples];
    let mut previous_series = vec![0.0; nobs * samples];
    let mut forces = vec![0.0; m * samples];
    // Friction forces and slip velocities `g_t . v` of the current period, then the 3-D
    // contacts' row forces and slip velocities.
    let nf = model.friction_count();
    let (nr, nd) = (model.row_count() - m - nf, model.frictional_contacts.len());
    let width = 2 * nf + nr + 2 * nd;
    let mut friction = vec![0.0; width * samples];
    let mut start = vec![0.0; 2 * n];
    let mut previous_start = vec![0.0; 2 * n];
    let record = |marcher: &TimeMarcher,
                  s: usize,
                  series: &mut [f64],
                  (forces, friction): (&mut [f64], &mut [f64])| {
        for (o, &dof) in observed_dofs.iter().enumerate() {
            series[s * nobs + o] = marcher.displacement()[dof];
        }
        forces[s * m..(s + 1) * m].copy_from_slice(marcher.contact_force());
        let (force, rest) = friction[width * s..width * (s + 1)].split_at_mut(nf);
        let (velocity, disks) = rest.split_at_mut(nf);
        force.copy_from_slice(marcher.friction_force());
        for (v, point) in velocity.iter_mut().zip(&model.friction) {
            *v = point.tangent.dot(marcher.velocity());
        }
        let (disk_force, disk_velocity) = disks.split_at_mut(nr);
        disk_force.copy_from_slice(marcher.frictional_force());
        marcher.frictional_slip_velocities(disk_velocity);
    };
    let mut change = f64::INFINITY;
    let h = marcher.step_size();
    let build = |marcher: &TimeMarcher,
                 series: &[f64],
                 (forces, friction): (&[f64], &[f64]),
                 periods: usize,
                 change: f64| {
        let friction_series = |offset: usize, count: usize| -> Vec<Vec<f64>> {
            (0..count)
                .map(|f| {
                    (0..samples)
                        .map(|s| friction[width * s + offset + f])
                        .collect()
                })
                .collect()
        };
        SteadyPeriod {
            scheme: marcher.scheme(),
            omega,
            times: (0..samples).map(|s| s as f64 * h).collect(),
            observed_dofs: observed_dofs.to_vec(),
            displacements: (0..nobs)
                .map(|o| (0..samples).map(|s| series[s * nobs + o]).collect())
                .collect(),
            contact_forces: (0..m)
                .map(|k| (0..samples).map(|s| forces[s * m + k]).collect())
                .collect(),
            friction_forces: friction_series(0, nf),
            slip_velocities: friction_series(nf, nf),
            frictional_forces: friction_series(2 * nf, nr),
            frictional_slip_velocities: friction_series(2 * nf + nr, 2 * nd),
            periods,
            period_change: change,
            counters: marcher.counters(),
            final_state: marcher.state(),
        }
    };
    for period in 1..=options.max_periods {
        for i in 0..n {
            start[i] = marcher.displacement()[i];
            start[n + i] = marcher.velocity()[i] / omega;
        }
        record(&marcher, 0, &mut series, (&mut forces, &mut friction));
        for s in 1..=spp {
            marcher.step()?;
            record(&marcher, s, &mut series, (&mut forces, &mut friction));
        }
        if period > 1 {
            change = relative_change(&start, &previous_start)
                .max(relative_change(&series, &previous_series));
            if change < options.tolerance {
                return Ok(build(
                    &marcher,
                    &series,
                    (&forces, &friction),
                    period,
                    change,
                ));
            }
        }
        if period == options.max_periods {
            break;
        }
        std::mem::swap(&mut series, &mut previous_series);
        std::mem::swap(&mut start, &mut previous_start);
    }
    Err(MarchError::NotSteady {
        periods: options.max_periods,
        change,
        last_period: Box::new(build(
            &marcher,
            &series,
            (&forces, &friction),
            options.max_periods,
            change,
        )),
    })
}
