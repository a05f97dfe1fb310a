//! Time-marching reference: march `M u'' + D u' + K u = f(t) + G^T lambda` from a given
//! state with a contact-aware one-step scheme until the response is periodic, then report
//! one steady period.
//!
//! # Schemes
//!
//! Two schemes that never let the contacts penetrate at the step level (each step's contact
//! problem is a small linear complementarity problem solved by the core's
//! [`Lemke`]):
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
//! The forcing is `f(t) = amplitude cos(omega t)`, `T = 2 pi / omega`, `h = T /
//! steps_per_period`; the march starts at `t = 0` (the forcing's cosine peak), so every
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
//! # What to expect (measured, canonical rod of issue 4)
//!
//! - Modified mass (trapezoidal): steady after 79 periods at tolerance 1e-8 from rest,
//!   about 0.1 s at 2000 steps per period (release). The tip touches the gap exactly
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
//! use semismooth_problems::march::{march_to_steady_state, MarchOptions};
//! use semismooth_problems::rod::{build_rod, MassModel, RodSpec};
//! let rod = build_rod(&RodSpec { mass: MassModel::Modified, ..RodSpec::canonical() }).unwrap();
//! let options = MarchOptions { steps_per_period: 200, tolerance: 1e-6, ..MarchOptions::default() };
//! let period = march_to_steady_state(&rod.model, &options, &[rod.tip_dof()]).unwrap();
//! let tip = &period.displacements[0];
//! assert!(tip.iter().all(|u| *u <= 0.5 + 1e-12)); // never beyond the gap
//! assert!(period.contact_forces[0].iter().all(|l| *l <= 0.0));
//! ```

use std::f64::consts::PI;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, Mat, MatMut, Par};
use semismooth::lemke::{Lemke, LemkeError, LemkeOptions, LemkeTermination};
use semismooth::linalg::LinearSolveError;

use crate::model::{sparse_mul_add, InvalidModel, SparseMatrix, StructuralModel};

/// The one-step scheme used to march.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum MarchScheme {
    /// [`MarchScheme::MasslessContactTrapezoidal`] when every contact dof has a zero mass
    /// row (or there is no contact), otherwise `MoreauJean { theta: 0.5, restitution: 0.0 }`.
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
            return Err(MarchError::InvalidOption {
                name: "steps_per_period",
                value: self.steps_per_period as f64,
                allowed: "an integer in 4..=100000000",
            });
        }
        if self.max_periods == 0 {
            return Err(MarchError::InvalidOption {
                name: "max_periods",
                value: 0.0,
                allowed: "an integer >= 1",
            });
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(MarchError::InvalidOption {
                name: "tolerance",
                value: self.tolerance,
                allowed: "a number in (0, 1)",
            });
        }
        if let MarchScheme::MoreauJean { theta, restitution } = self.scheme {
            if !(0.5..=1.0).contains(&theta) {
                return Err(MarchError::InvalidOption {
                    name: "theta",
                    value: theta,
                    allowed: "a number in [0.5, 1]",
                });
            }
            if !(0.0..=1.0).contains(&restitution) {
                return Err(MarchError::InvalidOption {
                    name: "restitution",
                    value: restitution,
                    allowed: "a number in [0, 1]",
                });
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
pub enum MarchError {
    /// An option is outside its allowed range.
    #[error("invalid option {name} = {value}: allowed {allowed}")]
    InvalidOption {
        /// The option's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// The model is not usable (sizes, non-finite data, frequency, contacts).
    #[error(transparent)]
    Model(#[from] InvalidModel),
    /// An observed dof does not exist.
    #[error("observed dof {dof} is out of range: the model has {dofs} dofs")]
    ObservedDofOutOfRange {
        /// The dof given.
        dof: usize,
        /// Number of dofs of the model.
        dofs: usize,
    },
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

/// Sparse LU with symbolic analysis and numeric factorization done once, and a kept
/// scratch buffer so that solves do not allocate.
struct SparseLu {
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    scratch: MemBuffer,
    n: usize,
}

impl SparseLu {
    fn new(a: &SparseMatrix) -> Result<Self, LinearSolveError> {
        let n = a.nrows();
        let symbolic = factorize_symbolic_lu(a.symbolic(), Default::default())
            .map_err(|e| LinearSolveError::from_faer(e, "analysing the iteration matrix"))?;
        let mut numeric = NumericLu::new();
        let mut buffer = MemBuffer::try_new(
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
        )
        .map_err(|_| LinearSolveError::OutOfMemory {
            during: "allocating the LU workspace",
        })?;
        symbolic
            .factorize_numeric_lu(
                &mut numeric,
                a.as_ref(),
                Par::Seq,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| LinearSolveError::from_sparse_lu(e, "factoring the iteration matrix"))?;
        let scratch = MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
            .map_err(|_| LinearSolveError::OutOfMemory {
                during: "allocating the solve workspace",
            })?;
        let mut lu = Self {
            symbolic,
            numeric,
            scratch,
            n,
        };
        lu.check(a)?;
        Ok(lu)
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
    }

    /// faer's sparse LU does not report small pivots: solve `A x = A 1` and check that
    /// `x` is finite and close to 1 (a singular or hopelessly ill-conditioned `A` fails).
    fn check(&mut self, a: &SparseMatrix) -> Result<(), LinearSolveError> {
        let ones = vec![1.0; self.n];
        let mut x = vec![0.0; self.n];
        sparse_mul_add(a.as_ref(), 1.0, &ones, &mut x);
        self.solve_in_place(&mut x);
        let error = x.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
        if error.is_finite() && error < 1e-6 {
            Ok(())
        } else {
            // A singular or hopelessly ill-conditioned matrix: the test solve's error stands
            // for the negligible pivot faer does not report.
            Err(LinearSolveError::Singular {
                index: 0,
                pivot: error,
                max_pivot: f64::NAN,
            })
        }
    }
}

/// `a K + b D + c M` (the pattern is the union of the three patterns).
fn combine(model: &StructuralModel, a: f64, b: f64, c: f64) -> Result<SparseMatrix, MarchError> {
    let mut triplets = Vec::new();
    let mut push = |m: &SparseMatrix, s: f64| {
        let r = m.as_ref();
        for j in 0..r.ncols() {
            for (i, v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
                triplets.push(Triplet::new(i, j, s * v));
            }
        }
    };
    push(&model.stiffness, a);
    if let Some(d) = &model.damping {
        push(d, b);
    }
    push(&model.mass, c);
    let n = model.dofs();
    SparseColMat::try_new_from_triplets(n, n, &triplets).map_err(|e| MarchError::Factorization {
        matrix: "iteration matrix",
        source: LinearSolveError::from_creation(e, "assembling the iteration matrix"),
    })
}

/// Largest absolute entry of column `j` (= row `j`, `M` is symmetric).
fn column_max_abs(m: &SparseMatrix, j: usize) -> f64 {
    m.as_ref()
        .val_of_col(j)
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()))
}

/// The scheme `Auto` resolves to for this model.
pub fn resolve_scheme(model: &StructuralModel, scheme: MarchScheme) -> MarchScheme {
    match scheme {
        MarchScheme::Auto => {
            if model
                .contacts
                .iter()
                .all(|c| column_max_abs(&model.mass, c.dof) == 0.0)
            {
                MarchScheme::MasslessContactTrapezoidal
            } else {
                MarchScheme::MOREAU_JEAN_DEFAULT
            }
        }
        other => other,
    }
}

/// Lemke workspaces, one per LCP size (so varying active sets never reallocate), and a
/// dense buffer for the active block of `W`.
struct ContactLcp {
    lemke: Vec<Lemke>,
    options: LemkeOptions,
    block: Mat<f64>,
}

impl ContactLcp {
    fn new(m: usize) -> Self {
        Self {
            lemke: (0..=m).map(Lemke::new).collect(),
            options: LemkeOptions::default(),
            block: Mat::zeros(m, m),
        }
    }

    /// Solves `w = q + W_AA z` for the contacts listed in `active` (the block is copied
    /// from the full `W`), writing `z` into `z[..active.len()]`; returns the pivots.
    fn solve(
        &mut self,
        w_full: &Mat<f64>,
        active: &[usize],
        q: &[f64],
        z: &mut [f64],
    ) -> Result<usize, LemkeError> {
        let a = active.len();
        for (jj, &j) in active.iter().enumerate() {
            for (ii, &i) in active.iter().enumerate() {
                self.block[(ii, jj)] = w_full[(i, j)];
            }
        }
        let report = self.lemke[a].solve(
            self.block.as_ref().submatrix(0, 0, a, a),
            &q[..a],
            &self.options,
        )?;
        if report.termination != LemkeTermination::Solved {
            return Err(LemkeError::NotSolved {
                termination: report.termination,
                pivots: report.pivots,
                complementarity_error: report.complementarity_error,
            });
        }
        // Lemke's z >= 0 up to round-off: clamp the (tiny) negative parts so that the
        // reported force has the right sign exactly.
        for (zi, ri) in z.iter_mut().zip(&report.z) {
            *zi = ri.max(0.0);
        }
        Ok(report.pivots)
    }
}

/// A one-step marcher: owns the factorization and every buffer, so that
/// [`TimeMarcher::step`] allocates nothing (except inside Lemke's report on steps with
/// an active contact).
pub struct TimeMarcher<'a> {
    model: &'a StructuralModel,
    scheme: MarchScheme,
    steps_per_period: usize,
    h: f64,
    /// `cos(2 pi j / steps_per_period)`, `j = 0..=steps_per_period`.
    cosines: Vec<f64>,
    /// Step index within the current period (0 at a period start).
    phase: usize,
    /// Periods completed.
    completed_periods: usize,
    lu: SparseLu,
    /// `Y = A^{-1} G^T` (N x m, column-major), `A` = K_eff or M_hat.
    y: Vec<f64>,
    /// `W = G Y` (m x m).
    w: Mat<f64>,
    lcp: ContactLcp,
    massless: Vec<bool>,
    u: Vec<f64>,
    v: Vec<f64>,
    /// Inertial force `M a` (trapezoidal only).
    r: Vec<f64>,
    lambda: Vec<f64>,
    rhs: Vec<f64>,
    tmp: Vec<f64>,
    q: Vec<f64>,
    z: Vec<f64>,
    active: Vec<usize>,
    counters: MarchCounters,
}

impl<'a> TimeMarcher<'a> {
    /// Validates the options, the model and the initial state, factors the iteration
    /// matrix and prepares `Y`, `W` and the initial inertial force. The time starts at 0.
    pub fn new(
        model: &'a StructuralModel,
        options: &MarchOptions,
        initial: &MarchState,
    ) -> Result<Self, MarchError> {
        options.validate()?;
        model.validate()?;
        let n = model.dofs();
        let m = model.contact_count();
        for (what, vec, len) in [
            ("displacement", &initial.displacement, n),
            ("velocity", &initial.velocity, n),
            ("contact_force", &initial.contact_force, m),
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
        let scheme = resolve_scheme(model, options.scheme);
        let massless: Vec<bool> = (0..n)
            .map(|j| column_max_abs(&model.mass, j) == 0.0)
            .collect();
        let spp = options.steps_per_period;
        let h = 2.0 * PI / model.forcing.omega / spp as f64;
        let (matrix, name) = match scheme {
            MarchScheme::MasslessContactTrapezoidal => {
                if let Some(c) = model.contacts.iter().find(|c| !massless[c.dof]) {
                    return Err(MarchError::MassiveContactDof {
                        dof: c.dof,
                        mass: column_max_abs(&model.mass, c.dof),
                    });
                }
                (combine(model, 1.0, 2.0 / h, 4.0 / (h * h))?, "K_eff")
            }
            MarchScheme::MoreauJean { theta, .. } => (
                combine(model, h * h * theta * theta, h * theta, 1.0)?,
                "M_hat",
            ),
            MarchScheme::Auto => unreachable!("resolved above"),
        };
        let mut lu = SparseLu::new(&matrix).map_err(|source| MarchError::Factorization {
            matrix: name,
            source,
        })?;
        let mut y = vec![0.0; n * m];
        let mut w = Mat::zeros(m, m);
        for (k, c) in model.contacts.iter().enumerate() {
            let col = &mut y[k * n..(k + 1) * n];
            col[c.dof] = 1.0;
            lu.solve_in_place(col);
            for (i, ci) in model.contacts.iter().enumerate() {
                w[(i, k)] = col[ci.dof];
            }
        }
        // Y = K_eff^{-1} G^T, column k for contact k.
        if let Some((index, &value)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(MarchError::Factorization {
                matrix: name,
                source: LinearSolveError::NonFiniteEntry {
                    row: index % n,
                    col: index / n,
                    value,
                },
            });
        }
        let cosines = (0..=spp)
            .map(|j| (2.0 * PI * j as f64 / spp as f64).cos())
            .collect();
        let mut marcher = Self {
            model,
            scheme,
            steps_per_period: spp,
            h,
            cosines,
            phase: 0,
            completed_periods: 0,
            lu,
            y,
            w,
            lcp: ContactLcp::new(m),
            massless,
            u: initial.displacement.clone(),
            v: initial.velocity.clone(),
            r: vec![0.0; n],
            lambda: initial.contact_force.clone(),
            rhs: vec![0.0; n],
            tmp: vec![0.0; n],
            q: vec![0.0; m],
            z: vec![0.0; m],
            active: Vec::with_capacity(m),
            counters: MarchCounters {
                factorizations: 1,
                linear_solves: m as u64 + 1,
                ..MarchCounters::default()
            },
        };
        if scheme == MarchScheme::MasslessContactTrapezoidal {
            marcher.equilibrium_inertia(0);
        }
        Ok(marcher)
    }

    /// `r = f(t_j) + G^T lambda - D v - K u`, zero on massless rows.
    fn equilibrium_inertia(&mut self, j: usize) {
        let model = self.model;
        let c = self.cosines[j];
        for (ri, ai) in self.r.iter_mut().zip(&model.forcing.amplitude) {
            *ri = c * ai;
        }
        for (ct, l) in model.contacts.iter().zip(&self.lambda) {
            self.r[ct.dof] += l;
        }
        if let Some(d) = &model.damping {
            sparse_mul_add(d.as_ref(), -1.0, &self.v, &mut self.r);
        }
        sparse_mul_add(model.stiffness.as_ref(), -1.0, &self.u, &mut self.r);
        for (ri, &ml) in self.r.iter_mut().zip(&self.massless) {
            if ml {
                *ri = 0.0;
            }
        }
    }

    /// The scheme in use (never `Auto`).
    pub fn scheme(&self) -> MarchScheme {
        self.scheme
    }

    /// The time step `h = T / steps_per_period`.
    pub fn step_size(&self) -> f64 {
        self.h
    }

    /// Current time, measured from the start of the march.
    pub fn time(&self) -> f64 {
        (self.completed_periods * self.steps_per_period + self.phase) as f64 * self.h
    }

    /// Step index within the current period (0 at a period start).
    pub fn phase(&self) -> usize {
        self.phase
    }

    /// Current displacements `u_n`.
    pub fn displacement(&self) -> &[f64] {
        &self.u
    }

    /// Current velocities `v_n`.
    pub fn velocity(&self) -> &[f64] {
        &self.v
    }

    /// Contact forces of the last step (`lambda <= 0`; impulse / h for Moreau–Jean).
    pub fn contact_force(&self) -> &[f64] {
        &self.lambda
    }

    /// The contact compliance `W = G A^{-1} G^T` of the per-step LCP (`A = K_eff` for the
    /// trapezoidal scheme, `M_hat` for Moreau–Jean).
    pub fn contact_compliance(&self) -> faer::MatRef<'_, f64> {
        self.w.as_ref()
    }

    /// Work so far.
    pub fn counters(&self) -> MarchCounters {
        self.counters
    }

    /// A copy of the current state.
    pub fn state(&self) -> MarchState {
        MarchState {
            displacement: self.u.clone(),
            velocity: self.v.clone(),
            contact_force: self.lambda.clone(),
        }
    }

    /// Advances one step.
    pub fn step(&mut self) -> Result<(), MarchError> {
        let j = self.phase;
        match self.scheme {
            MarchScheme::MasslessContactTrapezoidal => self.step_trapezoidal(j)?,
            MarchScheme::MoreauJean { theta, restitution } => {
                self.step_moreau_jean(j, theta, restitution)?
            }
            MarchScheme::Auto => unreachable!("resolved in new"),
        }
        self.counters.steps += 1;
        if self.u.iter().chain(&self.v).any(|x| !x.is_finite()) {
            return Err(MarchError::NonFinite {
                period: self.completed_periods + 1,
                step: j + 1,
            });
        }
        self.phase += 1;
        if self.phase == self.steps_per_period {
            self.phase = 0;
            self.completed_periods += 1;
        }
        Ok(())
    }

    fn lcp_error(&self, j: usize, source: LemkeError) -> MarchError {
        MarchError::ContactSolve {
            period: self.completed_periods + 1,
            step: j + 1,
            source,
        }
    }

    /// Solves the LCP `w = q + W_AA z` on the active contacts (none: `lambda = 0`), applies
    /// `rhs -= Y_A z` and sets `lambda_k = -z_k * force_scale`.
    fn solve_contacts(&mut self, j: usize, force_scale: f64) -> Result<(), MarchError> {
        self.lambda.fill(0.0);
        if self.active.is_empty() {
            return Ok(());
        }
        let n = self.u.len();
        let pivots = self
            .lcp
            .solve(&self.w, &self.active, &self.q, &mut self.z)
            .map_err(|err| self.lcp_error(j, err))?;
        self.counters.contact_solves += 1;
        self.counters.lemke_pivots += pivots as u64;
        let mut any = false;
        for (a, &k) in self.active.iter().enumerate() {
            let zk = self.z[a];
            if zk > 0.0 {
                any = true;
                self.lambda[k] = -zk * force_scale;
                let col = &self.y[k * n..(k + 1) * n];
                for (xi, yi) in self.rhs.iter_mut().zip(col) {
                    *xi -= yi * zk;
                }
            }
        }
        if any {
            self.counters.active_steps += 1;
        }
        Ok(())
    }

    fn step_trapezoidal(&mut self, j: usize) -> Result<(), MarchError> {
        let model = self.model;
        let n = self.u.len();
        let h = self.h;
        let c = self.cosines[j + 1];
        // rhs = f_{n+1} + r_n + M (4/h^2 u + 4/h v) + D (2/h u + v)
        for i in 0..n {
            self.rhs[i] = c * model.forcing.amplitude[i] + self.r[i];
            self.tmp[i] = 4.0 / (h * h) * self.u[i] + 4.0 / h * self.v[i];
        }
        sparse_mul_add(model.mass.as_ref(), 1.0, &self.tmp, &mut self.rhs);
        if let Some(d) = &model.damping {
            for i in 0..n {
                self.tmp[i] = 2.0 / h * self.u[i] + self.v[i];
            }
            sparse_mul_add(d.as_ref(), 1.0, &self.tmp, &mut self.rhs);
        }
        self.lu.solve_in_place(&mut self.rhs);
        self.counters.linear_solves += 1;
        // rhs = u_free. Contact LCP on all contacts (when one is closed): q = g - G u_free.
        self.active.clear();
        let mut closed = false;
        for (k, ct) in model.contacts.iter().enumerate() {
            self.q[k] = ct.gap - self.rhs[ct.dof];
            closed |= self.q[k] < 0.0;
        }
        if closed {
            self.active.extend(0..model.contacts.len());
        }
        self.solve_contacts(j, 1.0)?;
        // v_{n+1} = 2/h (u_{n+1} - u_n) - v_n; then u <- u_{n+1}.
        for i in 0..n {
            self.v[i] = 2.0 / h * (self.rhs[i] - self.u[i]) - self.v[i];
        }
        std::mem::swap(&mut self.u, &mut self.rhs);
        self.equilibrium_inertia(j + 1);
        Ok(())
    }

    fn step_moreau_jean(&mut self, j: usize, theta: f64, e: f64) -> Result<(), MarchError> {
        let model = self.model;
        let n = self.u.len();
        let h = self.h;
        let f_theta = theta * self.cosines[j + 1] + (1.0 - theta) * self.cosines[j];
        // rhs = M v - h D (1 - theta) v - h K (u + h theta (1 - theta) v) + h f_theta
        for i in 0..n {
            self.rhs[i] = h * f_theta * model.forcing.amplitude[i];
        }
        sparse_mul_add(model.mass.as_ref(), 1.0, &self.v, &mut self.rhs);
        if let Some(d) = &model.damping {
            sparse_mul_add(d.as_ref(), -h * (1.0 - theta), &self.v, &mut self.rhs);
        }
        for i in 0..n {
            self.tmp[i] = self.u[i] + h * theta * (1.0 - theta) * self.v[i];
        }
        sparse_mul_add(model.stiffness.as_ref(), -h, &self.tmp, &mut self.rhs);
        self.lu.solve_in_place(&mut self.rhs);
        self.counters.linear_solves += 1;
        // rhs = v_free. Active set from the predicted gap g - G (u + h/2 v).
        self.active.clear();
        for (k, ct) in model.contacts.iter().enumerate() {
            if ct.gap - (self.u[ct.dof] + 0.5 * h * self.v[ct.dof]) <= 0.0 {
                self.q[self.active.len()] = -(self.rhs[ct.dof] + e * self.v[ct.dof]);
                self.active.push(k);
            }
        }
        self.solve_contacts(j, 1.0 / h)?;
        // u_{n+1} = u_n + h (theta v_{n+1} + (1 - theta) v_n)
        for i in 0..n {
            self.u[i] += h * (theta * self.rhs[i] + (1.0 - theta) * self.v[i]);
        }
        std::mem::swap(&mut self.v, &mut self.rhs);
        Ok(())
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

/// Marches from rest until the period-to-period change is below the tolerance and returns
/// the last period (see the module docs).
pub fn march_to_steady_state(
    model: &StructuralModel,
    options: &MarchOptions,
    observed_dofs: &[usize],
) -> Result<SteadyPeriod, MarchError> {
    march_from_state(model, options, observed_dofs, &MarchState::rest(model))
}

/// Like [`march_to_steady_state`] but from a given state at `t = 0` (a warm start, e.g.
/// [`SteadyPeriod::final_state`] of a previous march).
pub fn march_from_state(
    model: &StructuralModel,
    options: &MarchOptions,
    observed_dofs: &[usize],
    initial: &MarchState,
) -> Result<SteadyPeriod, MarchError> {
    let mut marcher = TimeMarcher::new(model, options, initial)?;
    let n = model.dofs();
    let m = model.contact_count();
    if let Some(&dof) = observed_dofs.iter().find(|&&d| d >= n) {
        return Err(MarchError::ObservedDofOutOfRange { dof, dofs: n });
    }
    let spp = options.steps_per_period;
    let samples = spp + 1;
    let nobs = observed_dofs.len();
    let omega = model.forcing.omega;
    // Observed series of the current and previous periods, sample-major, and the
    // contact forces of the current period.
    let mut series = vec![0.0; nobs * samples];
    let mut previous_series = vec![0.0; nobs * samples];
    let mut forces = vec![0.0; m * samples];
    let mut start = vec![0.0; 2 * n];
    let mut previous_start = vec![0.0; 2 * n];
    let record = |marcher: &TimeMarcher, s: usize, series: &mut [f64], forces: &mut [f64]| {
        for (o, &dof) in observed_dofs.iter().enumerate() {
            series[s * nobs + o] = marcher.u[dof];
        }
        forces[s * m..(s + 1) * m].copy_from_slice(&marcher.lambda);
    };
    let mut change = f64::INFINITY;
    let h = marcher.h;
    let build =
        |marcher: &TimeMarcher, series: &[f64], forces: &[f64], periods: usize, change: f64| {
            SteadyPeriod {
                scheme: marcher.scheme,
                omega,
                times: (0..samples).map(|s| s as f64 * h).collect(),
                observed_dofs: observed_dofs.to_vec(),
                displacements: (0..nobs)
                    .map(|o| (0..samples).map(|s| series[s * nobs + o]).collect())
                    .collect(),
                contact_forces: (0..m)
                    .map(|k| (0..samples).map(|s| forces[s * m + k]).collect())
                    .collect(),
                periods,
                period_change: change,
                counters: marcher.counters,
                final_state: marcher.state(),
            }
        };
    for period in 1..=options.max_periods {
        for i in 0..n {
            start[i] = marcher.u[i];
            start[n + i] = marcher.v[i] / omega;
        }
        record(&marcher, 0, &mut series, &mut forces);
        for s in 1..=spp {
            marcher.step()?;
            record(&marcher, s, &mut series, &mut forces);
        }
        if period > 1 {
            change = relative_change(&start, &previous_start)
                .max(relative_change(&series, &previous_series));
            if change < options.tolerance {
                return Ok(build(&marcher, &series, &forces, period, change));
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
            &forces,
            options.max_periods,
            change,
        )),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lemke_step_lcp_agrees_with_the_closed_form_for_one_contact() {
        // m = 1: w = q + W z, z >= 0, w >= 0, w z = 0 has the unique solution
        // z = max(0, -q / W) for W > 0.
        let mut lcp = ContactLcp::new(1);
        let mut z = [0.0];
        for &(wv, q) in &[
            (0.3, -0.7),
            (2.5, 1e-3),
            (1e-4, -3.0),
            (7.0, 0.0),
            (1.0, -1e-14),
        ] {
            let w = Mat::from_fn(1, 1, |_, _| wv);
            lcp.solve(&w, &[0], &[q], &mut z).unwrap();
            let exact = f64::max(0.0, -q / wv);
            assert!(
                (z[0] - exact).abs() <= 1e-14 * exact.max(1.0),
                "W={wv} q={q}: {} vs {exact}",
                z[0]
            );
        }
    }

    #[test]
    fn lemke_step_lcp_on_an_active_subset_matches_enumeration() {
        // W symmetric positive definite 3x3, active set {0, 2}: compare with the solution
        // found by enumerating the 4 complementary index sets of the 2x2 block.
        let w = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 + i as f64 } else { 0.5 });
        let active = [0usize, 2];
        let q = [-1.0, 0.4];
        let mut lcp = ContactLcp::new(3);
        let mut z = [0.0; 3];
        lcp.solve(&w, &active, &q, &mut z).unwrap();
        let (a, b, d) = (w[(0, 0)], w[(0, 2)], w[(2, 2)]);
        let mut best = None;
        for mask in 0..4u32 {
            let mut zz = [0.0, 0.0];
            match mask {
                1 => zz[0] = -q[0] / a,
                2 => zz[1] = -q[1] / d,
                3 => {
                    let det = a * d - b * b;
                    zz[0] = (-q[0] * d + q[1] * b) / det;
                    zz[1] = (-q[1] * a + q[0] * b) / det;
                }
                _ => {}
            }
            let ww = [q[0] + a * zz[0] + b * zz[1], q[1] + b * zz[0] + d * zz[1]];
            if zz.iter().chain(&ww).all(|v| *v >= -1e-15) {
                best = Some(zz);
            }
        }
        let best = best.unwrap();
        assert!((z[0] - best[0]).abs() < 1e-14 && (z[1] - best[1]).abs() < 1e-14);
    }
}
