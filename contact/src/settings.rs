//! Solver settings: the method, its discretisation and its iterations, each with the
//! default that scenes, figures and tests share.

pub use crate::lcp::LcpScheme;

/// Solution method of a scene (`[solver] method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Method {
    /// Harmonic balance with exact contact as the Lipschitz equation, semismooth Newton
    /// (the paper).
    #[default]
    SsnHb,
    /// Harmonic balance with a penalty contact law `lambda = -k_p max(0, G u - g)`.
    PenaltyHb,
    /// Periodic time-domain LCP solved by Lemke's algorithm.
    LcpLemke,
    /// Periodic time-domain LCP `min(z, q + A z) = 0` solved by semismooth Newton.
    LcpSsn,
    /// Time marching to the steady state (the reference).
    March,
}

/// Globalization of the Newton iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum GlobalizationChoice {
    /// Full Newton steps.
    None,
    /// Armijo backtracking on `0.5 |F|^2`.
    Armijo,
    /// Non-monotone (Grippo–Lampariello–Lucidi) line search.
    Nonmonotone,
    /// Full steps for 30 iterations (active-set behaviour), then the non-monotone line
    /// search from the initial guess.
    Hybrid,
    /// The polyalgorithm (`semismooth::polyalgorithm::SolveOptions::Polyalgorithm`): up to 30 full
    /// steps (stopped early when they stagnate and the problem offers a smoothing); then,
    /// each from the initial guess, the smoothing path where the problem offers one (SSN-HB
    /// and the LCP's min map; penalty HB does not), the non-monotone line search on at most
    /// half of the iterations left, and the Newton homotopy `F(x) - (1 - t) F(x_0) = 0`; the
    /// report names the strategy that converged.
    #[default]
    Auto,
}

pub use crate::hb::DEFAULT_RELATIVE_PENALTY;

/// Default AFT sample count for `H` harmonics: the next power of two >= max(64, 4 (2H + 1))
/// ([`semismooth::harmonic::default_time_samples`]).
pub fn default_hb_time_samples(harmonics: usize) -> usize {
    semismooth::harmonic::default_time_samples(harmonics)
}

/// Validated solver settings (`[solver]`), defaults filled in.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverSettings {
    /// Method.
    pub method: Method,
    /// Number of harmonics `H` (harmonic-balance methods).
    pub harmonics: usize,
    /// AFT samples (HB) or time steps per period (LCP).
    pub time_samples: usize,
    /// Complementarity constant `c`; `None`: 10 x the static contact stiffness shared by
    /// the contacts that close together (`StructuralModel::default_complementarity_constant`).
    pub c: Option<f64>,
    /// Penalty stiffness `k_p` (absolute); `None`: 1e5 times the contact stiffness scale.
    pub penalty_stiffness: Option<f64>,
    /// Width of penalty HB's regularised friction law `-mu N tanh(v_t / eps)`, relative
    /// to each point's static slip ([`crate::hb::PenaltyHb::set_friction_regularisation`]).
    pub friction_regularisation: f64,
    /// Linear solver for HB Newton systems.
    pub linear_solver: LinearSolverChoice,
    /// Newton iteration limit.
    pub max_iterations: usize,
    /// Newton globalization.
    pub globalization: GlobalizationChoice,
    /// Absolute tolerance on the residual 2-norm (Newton methods).
    pub tolerance: f64,
    /// Time-marching steps per period.
    pub steps_per_period: usize,
    /// Time-marching period limit.
    pub max_periods: usize,
    /// Time-marching period-to-period tolerance.
    pub march_tolerance: f64,
    /// Restitution coefficient of the Moreau–Jean scheme (massive contact nodes).
    pub restitution: f64,
    /// Time discretisation of the periodic LCP (`lcp-lemke`, `lcp-ssn`).
    pub lcp_scheme: LcpScheme,
    /// Relative accuracy asked of the reported quantities (`[solver] accuracy`): the method
    /// then chooses its discretisation (harmonics and AFT samples, time steps) instead of
    /// taking `harmonics` / `time_samples` / `steps_per_period`
    /// ([`crate::accuracy::search`]); `None`: the discretisation as given.
    pub accuracy: Option<f64>,
    /// Whether a solve estimates its error ([`crate::accuracy::ErrorEstimate`]) by a second
    /// solve on a coarser discretisation (on by default; off where only the cost of the solve
    /// itself is measured).
    pub estimate_error: bool,
}

impl Default for SolverSettings {
    /// SSN-HB with the formulations' own defaults: harmonics and AFT samples of
    /// [`HbOptions`](crate::hb::HbOptions), time steps of
    /// [`PeriodicLcpOptions`](crate::lcp::PeriodicLcpOptions), iterations and tolerance of the
    /// core's [`NewtonOptions`](semismooth::newton::NewtonOptions), steps, periods and
    /// tolerance of [`MarchOptions`](crate::march::MarchOptions) (the scenes' defaults).
    fn default() -> Self {
        let hb = crate::hb::HbOptions::default();
        let lcp = crate::lcp::PeriodicLcpOptions::default();
        let newton = semismooth::newton::NewtonOptions::default();
        let march = crate::march::MarchOptions::default();
        Self {
            method: Method::SsnHb,
            harmonics: hb.harmonics,
            time_samples: hb
                .time_samples
                .unwrap_or_else(|| default_hb_time_samples(hb.harmonics)),
            c: hb.c,
            penalty_stiffness: None,
            friction_regularisation: crate::hb::DEFAULT_FRICTION_REGULARISATION,
            linear_solver: LinearSolverChoice::default(),
            max_iterations: newton.max_iterations,
            globalization: GlobalizationChoice::default(),
            tolerance: newton.tolerances.absolute_tolerance,
            steps_per_period: march.steps_per_period,
            max_periods: march.max_periods,
            march_tolerance: march.tolerance,
            restitution: 0.0,
            lcp_scheme: lcp.scheme,
            accuracy: None,
            estimate_error: true,
        }
    }
}

impl SolverSettings {
    /// The defaults ([`SolverSettings::default`]) with `harmonics` harmonics and the default
    /// AFT sample count for them.
    pub fn with_harmonics(harmonics: usize) -> Self {
        Self {
            harmonics,
            time_samples: default_hb_time_samples(harmonics),
            ..Self::default()
        }
    }
}

/// Validated sweep settings (`[sweep]`).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSettings {
    /// Start of the sweep, in units of omega_1.
    pub omega_ratio_from: f64,
    /// End of the sweep, in units of omega_1.
    pub omega_ratio_to: f64,
    /// Initial arclength step.
    pub step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Point limit.
    pub max_points: usize,
    /// Whether each point gets its Floquet multipliers (`[sweep] stability`).
    pub stability: bool,
    /// Whether an SSN-HB sweep with stability switches to the period-2 branch at its period
    /// doublings and follows it (`[sweep] period_two`; each branch costs a sweep at twice
    /// the harmonics).
    pub period_two: bool,
}

impl SweepSettings {
    /// A sweep from `omega_ratio_from` to `omega_ratio_to` (units of omega_1) with the
    /// scene defaults: `step = 0.01`, `min_step = 1e-5`, `max_step = 0.05`,
    /// `max_points = 2000`, `stability = true`, `period_two = false` (not validated; the
    /// sweep checks).
    pub fn new(omega_ratio_from: f64, omega_ratio_to: f64) -> Self {
        Self {
            omega_ratio_from,
            omega_ratio_to,
            step: 0.01,
            min_step: 1e-5,
            max_step: 0.05,
            max_points: 2000,
            stability: true,
            period_two: false,
        }
    }
}

/// Linear solver for the Newton systems of the harmonic-balance methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum LinearSolverChoice {
    /// Condensation onto the contact unknowns (per-harmonic sparse factorizations); the
    /// condensed SSN-HB system is factored dense up to
    /// [`KRYLOV_THRESHOLD`](crate::hb::KRYLOV_THRESHOLD) unknowns `m (2H + 1)` and solved
    /// matrix-free by GMRES above.
    #[default]
    Structured,
    /// Condensation with the condensed system always factored dense.
    CondensedDense,
    /// Condensation with the condensed SSN-HB system always solved matrix-free (GMRES).
    CondensedKrylov,
    /// Dense LU of the full Jacobian (for checking; cubic in the model size).
    Dense,
}

impl LinearSolverChoice {
    /// The scene's name of the choice (`linear_solver = "..."`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Structured => "structured",
            Self::CondensedDense => "condensed-dense",
            Self::CondensedKrylov => "condensed-krylov",
            Self::Dense => "dense",
        }
    }

    /// The condensed solve of the structured choices (`None` for the dense full LU).
    pub fn condensed(self) -> Option<crate::hb::CondensedSolve> {
        use crate::hb::CondensedSolve;
        match self {
            Self::Structured => Some(CondensedSolve::Auto),
            Self::CondensedDense => Some(CondensedSolve::Dense),
            Self::CondensedKrylov => Some(CondensedSolve::Krylov),
            Self::Dense => None,
        }
    }
}
