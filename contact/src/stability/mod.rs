//! Stability of a periodic harmonic-balance solution: the Floquet multipliers of the
//! perturbation equation along the solution's own contact phases.
//!
//! # The monodromy of the harmonic-balance orbit
//!
//! A harmonic-balance solution tells when each contact is closed: where its contact law's
//! switching function is positive (SSN-HB: `c (G u - g) - lambda > 0`, the samples the
//! generalized Jacobian treats as active; penalty HB: `G u - g > 0`), the interval ends
//! refined between the `Nt` AFT samples on the truncated series
//! ([`crate::hb::SsnHb::closed_intervals`], [`crate::hb::PenaltyHb::closed_intervals`]). Between two switching
//! instants the set of closed contacts is fixed and a small perturbation of the orbit
//! obeys a linear system with constant coefficients (module `phases`: the held dofs of
//! the closed contacts are removed, massless dofs follow statically or by first-order
//! dynamics); at the closing of a contact the perturbation jumps by a saltation matrix
//! that depends on the model only. The monodromy is the product, over one period, of the
//! exact propagators `exp(S_A tau)` of the phases and the saltations; its eigenvalues are
//! the Floquet multipliers, and the solution is stable when all have modulus `< 1`.
//!
//! This is Hill's method in the time domain: the harmonic-balance Jacobian Newton
//! factored is the Galerkin projection of the same perturbation equation (its contact
//! rows hold `G du = 0` on the active samples and `dlambda = 0` on the others), and
//! Hill's eigenvalue problem on it converges to these multipliers as `H` grows. Computing
//! them in the time domain avoids Hill's `2N (2H + 1)` eigenvalue problem and its sorting
//! of spurious eigenvalues: the phase matrices are `2N x 2N` at most, decomposed once per
//! set of closed contacts and reused along a sweep, so a point costs a few small dense
//! products (about the cost of its Newton solve; `docs/sweeps.md` has the measurements).
//!
//! # A cyclic sector
//!
//! A reduced cyclic sector's travelling wave is perturbed on every nodal diameter, not only
//! on its own interface phase, and its contact phases would read `K`, `M` without the
//! couplings: [`HbStability`] decides it by Hill's method over the nodal-diameter families
//! (module [`hill`]), each a sector problem with its own interface phase, their union the
//! full disk's Hill problem.
//!
//! # What the verdict means with a contact dof that carries mass
//!
//! Harmonic balance imposes no impact law: its contact holds in the Galerkin sense, and
//! the orbit's closed interval after an arrival with nonzero speed spans a couple of
//! periods of the highest harmonic whatever happens physically. What the orbit does at the
//! end of the interval tells which law it follows, and the monodromy uses that law:
//!
//! - The orbit stays on the obstacle and leaves it slower than it came (a release speed
//!   at most [`REBOUND`] times the approach speed; the rod with consistent mass, whose tip
//!   the rod behind it keeps pressed): a perfectly inelastic impact (restitution 0) that keeps the
//!   dof on the obstacle until the contact force returns to zero. Its saltation at the
//!   closing depends on the model only (module `phases`), and the interval is a phase with
//!   the dof held. Moreau–Jean marching with restitution 0 marches the same law
//!   (`contact/tests/stability_impacts.rs`).
//! - The orbit rebounds (a release speed above [`REBOUND`] times the approach speed; the
//!   two-dof chain with a stop on its mass, 0.97 to 1.0 at `H = 40`; an orbit grazing the
//!   stop): an impact with the orbit's restitution
//!   `e = min(1, release / approach)` at the interval's midpoint, followed by free flight.
//!   Its saltation `S = DR + (f+ - DR f-) n^T / (n^T f-)` (Müller 1995) carries the term
//!   `(1 + e) w a_c / v_c` (free acceleration over approach speed of the contact dof), which
//!   grows without bound towards grazing: the impacting orbits near a grazing contact are
//!   unstable, as the fixed-point index requires between a fold and a grazing point.
//!   Moreau–Jean marching with restitution 1 confirms the verdicts
//!   (`contact/tests/chain_stability.rs`).
//!
//! With a restitution between 0 and 1 time marching bounces where the orbit rests, or rests
//! where it bounces, and the two describe different dynamics.
//!
//! With every contact on a massless dof (modified mass) no impact law is needed: the
//! verdict is that of the semi-discrete model, and
//! [`map_stability`] (the discrete monodromy of the modified-mass trapezoidal map along the
//! map's own periodic orbit, found by a shooting Newton) confirms it where a multiplier is
//! close to the unit circle.
//!
//! # Where the verdict comes from near a fold
//!
//! The switching instants are those of the truncated series, so the multipliers carry the
//! harmonic-balance error; a multiplier through `+1` therefore crosses within that error of
//! the branch's fold, not exactly at it. Along a branch ([`crate::sweep::branch`]) the
//! number of real multipliers above `+1` changes parity at each fold (the sign of the
//! determinant of the harmonic-balance Jacobian, which the continuation's orientation
//! follows, is that of `prod (1 - mu)` over the real multipliers), and the branch analysis
//! uses this to place the crossing at the fold. The zigzags of a truncated balance
//! (reversals within the fold excursion) are not counted.

pub mod hill;
mod phases;
mod shooting;

use semismooth::floquet::{FloquetError, Multipliers};
use semismooth::InvalidOption;

use crate::hb::HbError;
use crate::march::{MarchError, MarchState};
use crate::model::{check_omega, StructuralModel};
use crate::settings::{Method, SolverSettings};
use crate::solve::{HarmonicProblem, Solution};

use phases::PhaseModel;
pub use phases::{ClosedContact, PhaseError};
pub use shooting::{map_stability, monodromy, MapStability};

/// Largest number of dofs for which a dense monodromy is formed.
pub const MAX_DOFS: usize = 400;

/// Default steps per period of the time-stepping map ([`map_stability`]).
pub const DEFAULT_STEPS_PER_PERIOD: usize = 2000;

/// Largest estimated work (floating-point operations) of one solution's monodromy: the
/// eigendecompositions of the phases not met before (`25 d^3` each) and the propagators
/// and products (`10 d^3` per phase), `d` the phase dimension. Above it the stability is
/// undecided ([`Undecided::TooCostly`]).
pub const MAX_WORK: f64 = 4e9;

/// A multiplier whose modulus is within this of 1 decides nothing (an undamped model).
pub const MARGINAL: f64 = 1e-9;

/// A closed interval of a contact on a dof with mass is an impact with rebound when the
/// orbit leaves the obstacle at more than this fraction of its approach speed (module
/// documentation). Measured: 0.97 to 1.0 on the two-dof chain with a stop on its mass
/// (`H = 40`); on the rod with consistent mass, whose tip the rod behind it keeps pressed,
/// -0.07 to 0.33 at `H = 20` and 0.55 to 0.87 at `H = 5` except within 5e-3 `omega_1` of
/// its first contact (0.93 to 1.0: the orbit grazes the stop and leaves it at once, as
/// Moreau–Jean marching with restitution 0 does there, and is unstable).
pub const REBOUND: f64 = 0.9;

/// Options of [`map_stability`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StabilityOptions {
    /// Steps per period of the trapezoidal map (`8..=1_000_000`), default
    /// [`DEFAULT_STEPS_PER_PERIOD`].
    pub steps_per_period: usize,
}

impl Default for StabilityOptions {
    fn default() -> Self {
        Self {
            steps_per_period: DEFAULT_STEPS_PER_PERIOD,
        }
    }
}

/// Why the stability could not be computed (bad input or a failed step); a solution whose
/// stability is not decided is an `Ok` with `stable: None`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StabilityError {
    /// An option or argument is outside its allowed range.
    #[error("invalid {name} = {value}: allowed {allowed}")]
    InvalidOption {
        /// Which option.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// The coefficient vector has the wrong length.
    #[error("harmonic coefficients: expected length {expected}, found {found}")]
    Dimension {
        /// `N (2H + 1)`.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A step of the time-stepping map failed.
    #[error(transparent)]
    March(#[from] MarchError),
    /// The eigenvalues could not be computed.
    #[error(transparent)]
    Floquet(#[from] FloquetError),
    /// The harmonic-balance problem of a branch could not be rebuilt.
    #[error(transparent)]
    Hb(#[from] HbError),
}

impl From<InvalidOption> for StabilityError {
    fn from(e: InvalidOption) -> Self {
        Self::InvalidOption {
            name: e.name,
            value: e.value,
            allowed: e.allowed,
        }
    }
}

/// Fewest harmonics with which a cyclic sector's stability is decided where its contacts
/// close (Hill's method): against the full disk's monodromy, a verdict differed at `H = 4`
/// and the leading multiplier was within 1e-2 at `H = 16` (`docs/cyclic.md`).
pub const SECTOR_CONTACT_HARMONICS: usize = 16;

/// Why a periodic solution's stability is not decided.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Undecided {
    /// A contact dof carries mass: the time-stepping map of [`map_stability`] has no
    /// impact law ([`hb_stability`] decides such solutions).
    MassCarryingContact,
    /// The model has Coulomb friction: the flow switches between stick and slip, and
    /// neither the contact phases of [`hb_stability`] nor the trapezoidal map of
    /// [`map_stability`] carry a friction law.
    Friction {
        /// The friction points.
        points: usize,
    },
    /// Contact `contact` acts on a general row of `G` (a combination of dofs): the contact
    /// phases hold single dofs fixed.
    GeneralContactRow {
        /// Its index.
        contact: usize,
    },
    /// The dense monodromy is formed only up to `limit` dofs.
    TooManyDofs {
        /// The model's dofs.
        dofs: usize,
        /// [`MAX_DOFS`].
        limit: usize,
    },
    /// The monodromy would cost more than [`MAX_WORK`].
    TooCostly {
        /// Contact phases per period.
        phases: usize,
        /// Estimated floating-point operations.
        work: f64,
    },
    /// A cyclic sector whose contacts close, analysed with fewer than
    /// [`SECTOR_CONTACT_HARMONICS`] harmonics: Hill's multipliers carry the Galerkin error
    /// of the sampled contact constraint, large enough there to turn verdicts.
    SectorContactHarmonics {
        /// The harmonics of the analysis.
        harmonics: usize,
    },
    /// The largest multiplier is on the unit circle to within [`MARGINAL`] (an undamped
    /// model).
    Marginal {
        /// Its modulus.
        max_abs: f64,
    },
    /// The phase dynamics could not be built.
    Phases(PhaseError),
    /// No periodic orbit of the time-stepping map was found near the harmonic-balance
    /// solution: Newton on the period map stopped.
    OrbitNotFound {
        /// Its termination.
        termination: semismooth::newton::Termination,
        /// Its iterations.
        iterations: usize,
        /// Its last `|F|`.
        residual_norm: f64,
    },
    /// Newton on the period map could not run.
    ShootingNotRun(semismooth::newton::NewtonError),
    /// Stability is computed for harmonic-balance solutions only.
    NotHarmonicBalance(Method),
    /// Stability was not asked for (`[sweep] stability = false`).
    NotRequested,
    /// The analysis failed.
    Failed(StabilityError),
}

/// The stability of one periodic solution ([`hb_stability`]).
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Stability {
    /// `Some(true)`: every multiplier inside the unit circle; `Some(false)`: one outside;
    /// `None`: not decided (see `undecided`).
    pub stable: Option<bool>,
    /// Largest modulus of the multipliers (`None` when not computed).
    pub floquet_max_abs: Option<f64>,
    /// The multipliers, by decreasing modulus (empty when not computed).
    pub multipliers: Multipliers,
    /// Why `stable` is `None`.
    pub undecided: Option<Undecided>,
    /// Contact phases per period (1 when the set of closed contacts never changes).
    pub phases: usize,
    /// Closings of a contact per period (each with its saltation).
    pub closings: usize,
}

impl Stability {
    /// Not decided, for `reason`.
    pub fn not_decided(reason: Undecided) -> Self {
        Self {
            undecided: Some(reason),
            ..Self::default()
        }
    }

    /// The verdict of `multipliers`: stable below 1, unstable above, undecided within
    /// [`MARGINAL`] of 1.
    pub fn of(multipliers: Multipliers, phases: usize, closings: usize) -> Self {
        let max_abs = multipliers.max_abs();
        let (stable, undecided) = if (max_abs - 1.0).abs() <= MARGINAL {
            (None, Some(Undecided::Marginal { max_abs }))
        } else {
            (Some(max_abs < 1.0), None)
        };
        Self {
            stable,
            floquet_max_abs: Some(max_abs),
            multipliers,
            undecided,
            phases,
            closings,
        }
    }

    /// The dominant multiplier `(re, im)` (`None` when not computed).
    pub fn dominant(&self) -> Option<(f64, f64)> {
        self.multipliers.dominant()
    }
}

/// The state `(u(t), v(t))` of a harmonic-balance solution: `u` holds the displacement
/// coefficients harmonic-major (`u[j N + dof]`, `j = 0`: mean, `2k - 1`: `cos(k w t)`,
/// `2k`: `sin(k w t)`). The contact forces are left at zero.
pub fn hb_state(
    model: &StructuralModel,
    harmonics: usize,
    omega: f64,
    u: &[f64],
    t: f64,
) -> Result<MarchState, StabilityError> {
    let n = model.dofs();
    let expected = n * (2 * harmonics + 1);
    if u.len() != expected {
        return Err(StabilityError::Dimension {
            expected,
            found: u.len(),
        });
    }
    let mut displacement = u[..n].to_vec();
    let mut velocity = vec![0.0; n];
    for k in 1..=harmonics {
        let kw = k as f64 * omega;
        let (s, c) = (kw * t).sin_cos();
        let (a, b) = (
            &u[(2 * k - 1) * n..2 * k * n],
            &u[2 * k * n..(2 * k + 1) * n],
        );
        for i in 0..n {
            displacement[i] += a[i] * c + b[i] * s;
            velocity[i] += kw * (b[i] * c - a[i] * s);
        }
    }
    Ok(MarchState {
        displacement,
        velocity,
        contact_force: vec![0.0; model.contact_count()],
    })
}

/// The stability analysis of harmonic-balance solutions of one model and method, reused
/// along a branch (the phases met are decomposed once).
#[non_exhaustive]
pub struct HbStability {
    formulation: HarmonicProblem,
    /// The model (the orbit's state at the impacts).
    model: StructuralModel,
    harmonics: usize,
    phases: Option<PhaseModel>,
    /// Why nothing is decided (too many dofs).
    refused: Option<Undecided>,
    /// A reduced cyclic sector: Hill's method over the nodal-diameter families
    /// ([`hill`]), not the contact phases (which read `K`, `M` without the couplings).
    sector: bool,
}

impl HbStability {
    /// The analysis of `settings`' harmonic-balance method on `model` (`Err` for another
    /// method or an invalid model).
    pub fn new(model: &StructuralModel, settings: &SolverSettings) -> Result<Self, StabilityError> {
        // The contact phases are fractions of the period: any valid frequency builds them.
        let omega = 1.0;
        let formulation = crate::solve::formulation::of(settings.method)
            .harmonic_problem(model, omega, settings)
            .ok_or(StabilityError::InvalidOption {
                name: "method",
                value: f64::NAN,
                allowed: "a harmonic-balance method (ssn-hb or penalty-hb)",
            })??;
        let closed = match formulation.closed_contact_stiffness() {
            None => ClosedContact::Held,
            Some(k) => ClosedContact::Spring(k),
        };
        let n = model.dofs();
        let sector = model.cyclic.is_some();
        let (phases, refused) = if model.has_friction() {
            (
                None,
                Some(Undecided::Friction {
                    points: model.friction.len() + model.frictional_contacts.len(),
                }),
            )
        } else if sector {
            (None, None)
        } else if let Some(contact) = model.contacts.iter().position(|c| c.direction().is_none()) {
            (None, Some(Undecided::GeneralContactRow { contact }))
        } else if n > MAX_DOFS {
            (
                None,
                Some(Undecided::TooManyDofs {
                    dofs: n,
                    limit: MAX_DOFS,
                }),
            )
        } else {
            (Some(PhaseModel::new(model, closed)), None)
        };
        Ok(Self {
            formulation,
            model: model.clone(),
            harmonics: settings.harmonics,
            phases,
            refused,
            sector,
        })
    }

    /// The closed intervals of every contact of the solution `x`, as fractions of the
    /// period ([`crate::hb::SsnHb::closed_intervals`], [`crate::hb::PenaltyHb::closed_intervals`]).
    pub fn closed_intervals(&self, x: &[f64]) -> Result<Vec<Vec<(f64, f64)>>, StabilityError> {
        self.formulation
            .closed_intervals(x)
            .map_err(StabilityError::from)
    }

    /// The stability of the solution `x` (the method's unknowns) at angular frequency
    /// `omega` (module documentation).
    pub fn of(&mut self, omega: f64, x: &[f64]) -> Result<Stability, StabilityError> {
        check_omega(omega)?;
        if let Some(reason) = &self.refused {
            return Ok(Stability::not_decided(reason.clone()));
        }
        let mut intervals = self.closed_intervals(x)?;
        if self.sector {
            return self.sector_stability(omega, &intervals);
        }
        // A contact held exactly rebounds at its impacts; a penalty spring does not.
        let rebounds = if self.formulation.closed_contact_stiffness().is_none() {
            self.rebounds(omega, x, &mut intervals)?
        } else {
            Vec::new()
        };
        let phases = self.phases.as_mut().expect("built when not refused");
        let period = 2.0 * std::f64::consts::PI / omega;
        switched_stability(phases, period, &intervals, &rebounds)
    }

    /// Hill's problem of the solution whose contacts are closed on `intervals`, at `omega`.
    fn hill_problem(&self, omega: f64, intervals: &[Vec<(f64, f64)>]) -> hill::HillProblem<'_> {
        let nt = self.formulation.time_samples();
        let active = (intervals.iter())
            .map(|iv| (0..nt).map(|n| holds(iv, n as f64 / nt as f64)).collect())
            .collect();
        hill::HillProblem {
            model: &self.model,
            harmonics: self.harmonics,
            omega,
            active,
            law: match self.formulation.closed_contact_stiffness() {
                Some(k) => hill::ClosedLaw::Penalty(k),
                None => hill::ClosedLaw::Multiplier(
                    (self.formulation.complementarity_constant()).unwrap_or(1.0),
                ),
            },
        }
    }

    /// The stability of a cyclic sector's solution over every nodal-diameter family
    /// ([`hill`]); [`Undecided::TooCostly`] above [`MAX_WORK`] (`30 d^3` per family, `d`
    /// the pencil's dimension).
    fn sector_stability(
        &self,
        omega: f64,
        intervals: &[Vec<(f64, f64)>],
    ) -> Result<Stability, StabilityError> {
        let problem = self.hill_problem(omega, intervals);
        let (families, _) = hill::families(&self.model);
        let size = (2 * self.harmonics + 1) as f64;
        let d = (2 * self.model.dofs() + intervals.len()) as f64 * size;
        let work = 30.0 * d.powi(3) * families.len() as f64;
        let (phases, closings) = switching_counts(&problem.active);
        let closes = problem.active.iter().flatten().any(|&closed| closed);
        if closes && self.harmonics < SECTOR_CONTACT_HARMONICS {
            return Ok(Stability::not_decided(Undecided::SectorContactHarmonics {
                harmonics: self.harmonics,
            }));
        }
        if work > MAX_WORK {
            return Ok(Stability::not_decided(Undecided::TooCostly {
                phases,
                work,
            }));
        }
        Ok(Stability::of(problem.multipliers()?, phases, closings))
    }

    /// The multipliers of one nodal-diameter family `family` (`0..N`, [`hill`]) of the
    /// solution `x` at `omega` by Hill's method; family 0 of a model that is not a cyclic
    /// sector is its whole Hill problem. `Err` for friction (no closed-contact law).
    pub fn family_multipliers(
        &self,
        omega: f64,
        x: &[f64],
        family: usize,
    ) -> Result<Multipliers, StabilityError> {
        check_omega(omega)?;
        self.refuse_friction()?;
        let intervals = self.closed_intervals(x)?;
        let values = self
            .hill_problem(omega, &intervals)
            .family_multipliers(family)?;
        Ok(Multipliers::from_values(values))
    }

    /// Every finite eigenvalue `(re, im)` of family `family`'s Hill pencil
    /// ([`HbStability::family_multipliers`]), each Floquet exponent with its copies shifted
    /// by multiples of `i omega`, in no particular order.
    pub fn family_exponents(
        &self,
        omega: f64,
        x: &[f64],
        family: usize,
    ) -> Result<Vec<(f64, f64)>, StabilityError> {
        check_omega(omega)?;
        self.refuse_friction()?;
        let intervals = self.closed_intervals(x)?;
        let exponents = self
            .hill_problem(omega, &intervals)
            .family_exponents(family)?;
        Ok(exponents.iter().map(|(_, l)| (l.re, l.im)).collect())
    }

    /// `Err` for a model with friction (Hill's problem here has no friction law).
    fn refuse_friction(&self) -> Result<(), StabilityError> {
        if self.model.has_friction() {
            return Err(StabilityError::InvalidOption {
                name: "friction points",
                value: (self.model.friction.len() + self.model.frictional_contacts.len()) as f64,
                allowed: "none: Hill's method here carries no friction law",
            });
        }
        Ok(())
    }

    /// The closed intervals of contacts on dofs with mass that the orbit `x` leaves at
    /// more than [`REBOUND`] times its approach speed, removed from `intervals` and
    /// returned as impacts with the orbit's restitution at their midpoints.
    fn rebounds(
        &self,
        omega: f64,
        x: &[f64],
        intervals: &mut [Vec<(f64, f64)>],
    ) -> Result<Vec<Rebound>, StabilityError> {
        let Some(phases) = self.phases.as_ref() else {
            return Ok(Vec::new());
        };
        if phases.first_order_massless() {
            return Ok(Vec::new());
        }
        let (model, h) = (&self.model, self.harmonics);
        let u = &x[..model.dofs() * (2 * h + 1)];
        let period = 2.0 * std::f64::consts::PI / omega;
        let mut rebounds = Vec::new();
        for (contact, closed) in intervals.iter_mut().enumerate() {
            if !phases.impacts(contact) {
                continue;
            }
            let point = &model.contacts[contact];
            let (dof, sign) = (point.dof(), point.row.coefficients()[0]);
            let mut kept = Vec::with_capacity(closed.len());
            for &(a, b) in closed.iter() {
                if b - a >= 1.0 {
                    kept.push((a, b));
                    continue;
                }
                let arrival = hb_state(model, h, omega, u, a * period)?;
                let departure = hb_state(model, h, omega, u, b * period)?;
                let approach = sign * arrival.velocity[dof];
                let leave = -sign * departure.velocity[dof];
                if !(approach > 0.0 && leave > REBOUND * approach) {
                    kept.push((a, b));
                    continue;
                }
                let time = (0.5 * (a + b)).rem_euclid(1.0);
                let mut at = hb_state(model, h, omega, u, time * period)?;
                at.displacement[dof] = sign * point.gap;
                rebounds.push(Rebound {
                    time,
                    contact,
                    restitution: (leave / approach).min(1.0),
                    displacement: at.displacement,
                    velocity: arrival.velocity,
                    load_phase: 2.0 * std::f64::consts::PI * time,
                });
            }
            *closed = kept;
        }
        Ok(rebounds)
    }
}

/// The stability of the solution `x` of `settings`' harmonic-balance method at `omega`
/// ([`HbStability`] for one solution).
pub fn hb_stability(
    model: &StructuralModel,
    settings: &SolverSettings,
    omega: f64,
    x: &[f64],
) -> Result<Stability, StabilityError> {
    HbStability::new(model, settings)?.of(omega, x)
}

/// The stability of `solution`, a harmonic-balance solve on `model`, from what it carries
/// (its settings, frequency and state; [`hb_stability`]).
pub fn solution_stability(
    model: &StructuralModel,
    solution: &Solution,
) -> Result<Stability, StabilityError> {
    hb_stability(model, &solution.settings, solution.omega, &solution.state)
}

/// An impact with rebound of a contact on a dof with mass: the orbit's closed interval
/// collapsed to its midpoint `time` (fraction of the period), with the orbit's restitution
/// and its state just before.
struct Rebound {
    time: f64,
    contact: usize,
    restitution: f64,
    displacement: Vec<f64>,
    velocity: Vec<f64>,
    /// The load's phase `omega t` at the impact.
    load_phase: f64,
}

/// The contact phases per period (sample indices where the set of closed contacts
/// changes, at least 1) and the closings (a contact's samples going from open to closed)
/// of the switching samples `active`.
fn switching_counts(active: &[Vec<bool>]) -> (usize, usize) {
    let nt = active.first().map_or(0, Vec::len);
    let changes = (0..nt)
        .filter(|&n| active.iter().any(|a| a[n] != a[(n + nt - 1) % nt]))
        .count();
    let closings = (active.iter())
        .map(|a| (0..nt).filter(|&n| a[n] && !a[(n + nt - 1) % nt]).count())
        .sum();
    (changes.max(1), closings)
}

/// Whether contact phase intervals `intervals` hold the fraction `t` of the period.
fn holds(intervals: &[(f64, f64)], t: f64) -> bool {
    intervals
        .iter()
        .any(|&(a, b)| (a <= t && t < b) || (a <= t + 1.0 && t + 1.0 < b))
}

/// The closed contacts at the fraction `t` of the period.
fn closed_at(intervals: &[Vec<(f64, f64)>], t: f64) -> Vec<usize> {
    (0..intervals.len())
        .filter(|&i| holds(&intervals[i], t))
        .collect()
}

/// The monodromy of the contact phases `intervals` (per contact, fractions of the period)
/// of an orbit of period `period`, and its verdict (module documentation).
fn switched_stability(
    phases: &mut PhaseModel,
    period: f64,
    intervals: &[Vec<(f64, f64)>],
    rebounds: &[Rebound],
) -> Result<Stability, StabilityError> {
    let mut times: Vec<f64> = intervals
        .iter()
        .flat_map(|iv| {
            iv.iter()
                .filter(|(a, b)| b - a < 1.0)
                .flat_map(|&(a, b)| [a.rem_euclid(1.0), b.rem_euclid(1.0)])
        })
        .chain(rebounds.iter().map(|r| r.time))
        .collect();
    times.sort_by(f64::total_cmp);
    times.dedup();
    let estimate = |sets: &[Vec<usize>], phases: &PhaseModel| -> f64 {
        let d = 2.0 * phases.dofs() as f64;
        let fresh = sets.iter().filter(|s| !phases.has_phase(s)).count() as f64;
        25.0 * d.powi(3) * fresh + 10.0 * d.powi(3) * sets.len() as f64
    };
    let phase_err = |e: PhaseError| Undecided::Phases(e);
    if times.is_empty() {
        let set = closed_at(intervals, 0.5);
        let work = estimate(std::slice::from_ref(&set), phases);
        if work > MAX_WORK {
            return Ok(Stability::not_decided(Undecided::TooCostly {
                phases: 1,
                work,
            }));
        }
        let phase = match phases.phase(&set) {
            Ok(p) => p,
            Err(e) => return Ok(Stability::not_decided(phase_err(e))),
        };
        let multipliers = match phase.propagator_eigenvalues(period) {
            Some(values) => Multipliers::from_values(values),
            None => Multipliers::of(phase.propagator(period).as_ref())?,
        };
        return Ok(Stability::of(multipliers, 1, 0));
    }
    let k = times.len();
    let sets: Vec<Vec<usize>> = (0..k)
        .map(|j| {
            let end = if j + 1 < k {
                times[j + 1]
            } else {
                times[0] + 1.0
            };
            closed_at(intervals, 0.5 * (times[j] + end))
        })
        .collect();
    let work = estimate(&sets, phases);
    if work > MAX_WORK {
        return Ok(Stability::not_decided(Undecided::TooCostly {
            phases: k,
            work,
        }));
    }
    match monodromy_of_phases(phases, period, &times, &sets, rebounds) {
        Ok((monodromy, closings)) => {
            let multipliers = Multipliers::of(monodromy.as_ref())?;
            Ok(Stability::of(multipliers, k, closings))
        }
        Err(e) => Ok(Stability::not_decided(phase_err(e))),
    }
}

/// The product of the phase propagators and the closing and rebound saltations over one
/// period, starting after the switch at `times[0]`, on the coordinates of phase `sets[0]`;
/// and the number of closings and rebounds.
fn monodromy_of_phases(
    phases: &mut PhaseModel,
    period: f64,
    times: &[f64],
    sets: &[Vec<usize>],
    rebounds: &[Rebound],
) -> Result<(semismooth::faer::Mat<f64>, usize), PhaseError> {
    let k = times.len();
    let d0 = phases.phase(&sets[0])?.dim();
    let mut y = semismooth::faer::Mat::<f64>::identity(d0, d0);
    let mut closings = 0;
    for j in 0..k {
        let end = if j + 1 < k {
            times[j + 1]
        } else {
            times[0] + 1.0
        };
        let tau = (end - times[j]) * period;
        y = &phases.phase(&sets[j])?.propagator(tau) * &y;
        let switch = times[(j + 1) % k];
        for r in rebounds.iter().filter(|r| r.time == switch) {
            let state = (r.displacement.as_slice(), r.velocity.as_slice());
            if let Some(s) =
                phases.rebound(&sets[j], r.contact, r.restitution, state, r.load_phase)?
            {
                y = &s * &y;
                closings += 1;
            }
        }
        let next = &sets[(j + 1) % k];
        let mut pre = sets[j].clone();
        for &c in next.iter().filter(|c| !sets[j].contains(c)) {
            let s = phases.saltation(&pre, c)?;
            y = &s * &y;
            let mut post = pre.clone();
            post.push(c);
            post.sort_unstable();
            y = &phases.transfer(&pre, &post)? * &y;
            pre = post;
            closings += 1;
        }
        if &pre != next {
            y = &phases.transfer(&pre, next)? * &y;
        }
    }
    Ok((y, closings))
}
