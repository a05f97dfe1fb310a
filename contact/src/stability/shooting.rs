//! The discrete monodromy of the modified-mass time-stepping map along the map's own
//! periodic orbit next to a harmonic-balance solution: the confirmation of a multiplier
//! close to the unit circle ([`super`]), for contacts on massless dofs.
//!
//! # Mathematics
//!
//! With every contact dof massless (modified mass), the massless dofs follow the massive
//! ones through quasi-static equilibrium (a static complementarity problem at each
//! instant; with stiffness-proportional damping a massless dof keeps a first-order
//! dynamics), the vector field is piecewise linear and Lipschitz and the variational
//! equation along a periodic orbit is well defined. The trapezoidal scheme of
//! [`crate::march`] (`MasslessContactTrapezoidal`) is a piecewise-affine map of the state
//! `(u, v)`: with the set of closed contacts of a step fixed its linear part `T_A` does not
//! depend on the state or on time ([`TimeMarcher::step_tangent`]). The discrete monodromy
//! of an orbit with `n_s` steps per period is
//!
//! ```text
//! Phi = T_{A(n_s - 1)} ... T_{A(1)} T_{A(0)},
//! ```
//!
//! `A(j)` the contacts closed on step `j` of the orbit. Consecutive steps with the same set
//! share one matrix power, so the cost is a few dense `2N x 2N` products
//! (`O(N^3 log n_s)`), which limits the dense monodromy to [`MAX_DOFS`] dofs.
//!
//! *Which orbit.* The harmonic-balance solution satisfies the contact law only in the
//! Galerkin sense, so its reconstructed states are not an orbit of the map, and the
//! contacts its single steps close differ from those of a true orbit near the closing and
//! opening instants (measured on the strongly forced rod: 262 instead of 296 contact steps
//! out of 2000, a multiplier 1.08 instead of 0.82 that also drifted with the step). The
//! linearisation is therefore taken along the periodic orbit of the map itself, found by
//! semismooth Newton (the core's driver) on the period map `Phi(x) - x = 0` started from
//! the harmonic-balance state at `t = 0`, with the generalized Jacobian `Phi'(x) - I` (the
//! map is piecewise affine: Newton ends once the contact steps are right, 1-5 iterations
//! on that rod). That orbit is the one time marching converges to when it is stable; it is
//! within about 1e-2 (relative, displacements at `t = 0`) of the harmonic-balance state on
//! contact branches. Where no orbit of the map lies near the harmonic-balance solution
//! (next to a fold the two discretisations fold at slightly different frequencies) the
//! answer is `stable: None` with Newton's outcome as the reason. The multipliers converge
//! with the step (largest modulus 0.8208 / 0.8209 / 0.8216 at 1000 / 2000 / 4000 steps per
//! period on an upper-branch point of that rod).
//!
//! The velocity of a massless dof whose column of `D` vanishes on the massless rows (no
//! damping there) never influences the map: it only rings with a factor `-1` per step, an
//! artefact of the trapezoidal velocity. Those rows and columns are removed before the
//! eigenvalues are computed ([`semismooth::floquet`]). What remains has zero multipliers
//! for the directions that violate the massless equilibrium (projected away by one step).
//!
//! The solution is stable when every multiplier has modulus `< 1`. With a contact on a dof
//! that has mass (consistent or lumped mass) the flow has impacts and its monodromy needs
//! the impact law's saltation matrices: the answer is then `stable: None` with that
//! reason; likewise above [`MAX_DOFS`].
//!
//! # Validation
//!
//! `tests/stability.rs` marches the model from the harmonic-balance state plus a small
//! perturbation and compares the per-period decay (stable) or growth (unstable) of the
//! distance between successive periods with the largest multiplier.

use semismooth::faer::Mat;
use semismooth::floquet::Multipliers;
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::{NewtonReport, Termination};
use semismooth::polyalgorithm::{self, PolyalgorithmOptions};
use semismooth::{EvaluationError, GeneralizedJacobian, Residual};

use super::{hb_state, StabilityError, StabilityOptions, Undecided, MAX_DOFS};
use crate::march::{resolve_scheme, MarchOptions, MarchScheme, MarchState, TimeMarcher};
use crate::model::{check_omega, StructuralModel};

/// The stability of one periodic solution from the discrete monodromy of the time-stepping
/// map along the map's own periodic orbit.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MapStability {
    /// `Some(true)`: every multiplier inside the unit circle; `Some(false)`: one outside;
    /// `None`: not decided (see `undecided`).
    pub stable: Option<bool>,
    /// Largest modulus of the multipliers (`None` when not computed).
    pub floquet_max_abs: Option<f64>,
    /// The multipliers, by decreasing modulus (empty when not computed).
    pub multipliers: Multipliers,
    /// Why `stable` is `None`.
    pub undecided: Option<Undecided>,
    /// Steps per period of the map.
    pub steps_per_period: usize,
    /// Steps of the orbit with at least one closed contact.
    pub contact_steps: usize,
    /// `|u* - u_HB| / |u_HB|` between the displacements of the periodic orbit of the map and
    /// of the harmonic-balance solution at `t = 0` (`None` when not computed).
    pub orbit_distance: Option<f64>,
    /// Newton iterations on the period map (0 when no contact closes along the orbit: the
    /// map is then affine and its monodromy is known without the orbit).
    pub shooting_iterations: usize,
    /// The periodic orbit's state at `t = 0` (`None` when not computed); when no contact
    /// closes along it, the harmonic-balance state (within the time-step error of the
    /// map's orbit; `orbit_distance` is then `None`).
    pub orbit: Option<MarchState>,
}

impl MapStability {
    /// Not decided, for `reason`.
    pub fn not_decided(reason: Undecided, steps_per_period: usize) -> Self {
        Self {
            stable: None,
            floquet_max_abs: None,
            multipliers: Multipliers::default(),
            undecided: Some(reason),
            steps_per_period,
            contact_steps: 0,
            orbit_distance: None,
            shooting_iterations: 0,
            orbit: None,
        }
    }

    /// The dominant multiplier `(re, im)` (`None` when not computed).
    pub fn dominant(&self) -> Option<(f64, f64)> {
        self.multipliers.dominant()
    }
}

/// `a^k` by repeated squaring (`k >= 1`).
fn power(a: &Mat<f64>, mut k: usize) -> Mat<f64> {
    let mut base = a.clone();
    let mut result: Option<Mat<f64>> = None;
    while k > 0 {
        if k & 1 == 1 {
            result = Some(match result {
                None => base.clone(),
                Some(r) => &base * &r,
            });
        }
        k >>= 1;
        if k > 0 {
            base = &base * &base;
        }
    }
    result.unwrap_or_else(|| Mat::identity(a.nrows(), a.ncols()))
}

/// Floquet multipliers of the time-stepping map's periodic orbit next to the
/// harmonic-balance solution with displacement coefficients `u` (`H = harmonics`) at
/// angular frequency `omega` (module documentation).
pub fn map_stability(
    model: &StructuralModel,
    harmonics: usize,
    omega: f64,
    u: &[f64],
    options: &StabilityOptions,
) -> Result<MapStability, StabilityError> {
    let spp = options.steps_per_period;
    if let Some(undecided) = map_undecided(model, harmonics, omega, u, spp)? {
        return Ok(undecided);
    }
    let march = MarchOptions {
        steps_per_period: spp,
        scheme: MarchScheme::MasslessContactTrapezoidal,
        ..MarchOptions::default()
    };
    let mut marcher = TimeMarcher::new(model, omega, &march, &MarchState::rest(model))?;
    marcher.set_closed_contact_velocity_reset(true);
    let keep = influential(&marcher);
    let start = hb_state(model, harmonics, omega, u, 0.0)?;
    if orbit_stays_open(model, harmonics, u) {
        // No contact closes along the orbit: the map is affine with the linear part of the
        // open contacts, whatever the orbit; its monodromy needs no shooting.
        let runs = vec![(Vec::new(), spp)];
        let multipliers = reduced_multipliers(&monodromy(&mut marcher, &runs)?, &keep)?;
        return Ok(MapStability {
            stable: Some(multipliers.is_stable()),
            floquet_max_abs: Some(multipliers.max_abs()),
            multipliers,
            undecided: None,
            steps_per_period: spp,
            contact_steps: 0,
            orbit_distance: None,
            shooting_iterations: 0,
            orbit: Some(start),
        });
    }
    let full: Vec<f64> = start
        .displacement
        .iter()
        .chain(&start.velocity)
        .copied()
        .collect();
    let mut x: Vec<f64> = keep.iter().map(|&i| full[i]).collect();
    let x_hb = x.clone();
    let mut shooting = Shooting {
        marcher,
        keep,
        full,
        runs: Vec::new(),
        evaluated: None,
    };
    let report = match shooting.orbit(&mut x, spp)? {
        Ok(report) => report,
        Err(undecided) => return Ok(undecided),
    };
    shooting.period(&x)?;
    let keep = &shooting.keep;
    let multipliers =
        reduced_multipliers(&monodromy(&mut shooting.marcher, &shooting.runs)?, keep)?;
    let distance = orbit_distance(keep, model.dofs(), &x, &x_hb);
    let contact_steps = shooting
        .runs
        .iter()
        .filter(|(set, _)| !set.is_empty())
        .map(|(_, c)| c)
        .sum();
    Ok(MapStability {
        stable: Some(multipliers.is_stable()),
        floquet_max_abs: Some(multipliers.max_abs()),
        multipliers,
        undecided: None,
        steps_per_period: spp,
        contact_steps,
        orbit_distance: Some(distance),
        shooting_iterations: report.iterations,
        orbit: Some(shooting.state(&x, model.contact_count())),
    })
}

/// `Err` for a bad step count, frequency or size of `u`; the answer without a monodromy
/// (with friction, a contact on a dof with mass, more than [`MAX_DOFS`] dofs), `None`
/// when the map's monodromy decides.
fn map_undecided(
    model: &StructuralModel,
    harmonics: usize,
    omega: f64,
    u: &[f64],
    spp: usize,
) -> Result<Option<MapStability>, StabilityError> {
    if !(8..=1_000_000).contains(&spp) {
        return Err(StabilityError::InvalidOption {
            name: "steps_per_period",
            value: spp as f64,
            allowed: "an integer in 8..=1000000",
        });
    }
    check_omega(omega)?;
    let n = model.dofs();
    if u.len() != n * (2 * harmonics + 1) {
        return Err(StabilityError::Dimension {
            expected: n * (2 * harmonics + 1),
            found: u.len(),
        });
    }
    let reason = if model.has_friction() {
        let points = model.friction.len() + model.frictional_contacts.len();
        Undecided::Friction { points }
    } else if resolve_scheme(model, MarchScheme::Auto) != MarchScheme::MasslessContactTrapezoidal {
        Undecided::MassCarryingContact
    } else if n > MAX_DOFS {
        Undecided::TooManyDofs {
            dofs: n,
            limit: MAX_DOFS,
        }
    } else {
        return Ok(None);
    };
    Ok(Some(MapStability::not_decided(reason, spp)))
}

/// `|u* - u_HB| / |u_HB|` between the displacements (the components of `keep` below
/// `dofs`) of the orbit's state `x` and the harmonic-balance state `x_hb`.
fn orbit_distance(keep: &[usize], dofs: usize, x: &[f64], x_hb: &[f64]) -> f64 {
    let displacements = |x: &[f64]| -> Vec<f64> {
        keep.iter()
            .zip(x)
            .filter(|(i, _)| **i < dofs)
            .map(|(_, v)| *v)
            .collect()
    };
    let (u_orbit, u_hb) = (displacements(x), displacements(x_hb));
    u_orbit
        .iter()
        .zip(&u_hb)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
        / u_hb
            .iter()
            .map(|a| a * a)
            .sum::<f64>()
            .sqrt()
            .max(f64::MIN_POSITIVE)
}

/// The multipliers of `monodromy` restricted to the influential components `keep`.
fn reduced_multipliers(
    monodromy: &Mat<f64>,
    keep: &[usize],
) -> Result<Multipliers, StabilityError> {
    let reduced = Mat::from_fn(keep.len(), keep.len(), |i, j| monodromy[(keep[i], keep[j])]);
    Ok(Multipliers::of(reduced.as_ref())?)
}

/// Whether every contact stays open along the harmonic-balance orbit with a margin: at each
/// contact, `s u_0 + sum_k |(a_k, b_k)| <= g - OPEN_MARGIN (|g| + sum_k |(a_k, b_k)|)` (a bound
/// of `s u(t)` over the period; `s` the contact's direction). The margin covers the distance
/// between the harmonic-balance orbit and the map's own (the time-step error, about
/// `(2 pi / n_s)^2` relative).
fn orbit_stays_open(model: &StructuralModel, harmonics: usize, u: &[f64]) -> bool {
    let n = model.dofs();
    model.contacts.iter().all(|c| {
        let amplitude: f64 = (1..=harmonics)
            .map(|k| {
                let (a, b) = (c.row.dot_at(u, (2 * k - 1) * n), c.row.dot_at(u, 2 * k * n));
                a.hypot(b)
            })
            .sum();
        let highest = c.row.dot(u) + amplitude;
        highest <= c.gap - OPEN_MARGIN * (c.gap.abs() + amplitude)
    })
}

/// Relative margin of [`orbit_stays_open`].
const OPEN_MARGIN: f64 = 1e-3;

/// `|F|` of the period map's Newton solve relative to the largest state entry.
pub(crate) const SHOOTING_TOLERANCE: f64 = 1e-9;

/// The state components that influence the map: every displacement, the velocities of
/// dofs with mass, and those of massless dofs with a damping entry on a massless row
/// (module documentation).
fn influential(marcher: &TimeMarcher) -> Vec<usize> {
    let n = marcher.displacement().len();
    (0..2 * n)
        .filter(|&c| {
            if c < n || !marcher.is_massless(c - n) {
                return true;
            }
            let j = c - n;
            marcher.model().damping.as_ref().is_some_and(|d| {
                let d = d.as_ref();
                d.row_idx_of_col(j)
                    .zip(d.val_of_col(j))
                    .any(|(i, v)| marcher.is_massless(i) && *v != 0.0)
            })
        })
        .collect()
}

/// The discrete monodromy (`2N x 2N` on `(u, v)`) of `marcher`'s map over the runs
/// `(closed contacts, steps)` of one period.
pub fn monodromy(
    marcher: &mut TimeMarcher,
    runs: &[(Vec<usize>, usize)],
) -> Result<Mat<f64>, StabilityError> {
    let n = marcher.displacement().len();
    let mut tangents: Vec<(Vec<usize>, Mat<f64>)> = Vec::new();
    let mut monodromy = Mat::<f64>::identity(2 * n, 2 * n);
    for (set, count) in runs {
        let index = match tangents.iter().position(|(s, _)| s == set) {
            Some(i) => i,
            None => {
                tangents.push((set.clone(), marcher.step_tangent(set)?));
                tangents.len() - 1
            }
        };
        monodromy = &power(&tangents[index].1, *count) * &monodromy;
    }
    Ok(monodromy)
}

/// The period map of the trapezoidal scheme as the equation `Phi(x) - x = 0` on the
/// influential components `x` of `(u, v)` at `t = 0` (the others stay as given), with the
/// generalized Jacobian `Phi'(x) - I` from the closed contacts of the march.
struct Shooting<'a> {
    marcher: TimeMarcher<'a>,
    keep: Vec<usize>,
    /// The full `(u, v)`: the components not in `keep` keep their values.
    full: Vec<f64>,
    /// Runs `(closed contacts, steps)` of the last period marched.
    runs: Vec<(Vec<usize>, usize)>,
    /// The `x` the runs belong to and the period's end state.
    evaluated: Option<(Vec<f64>, Vec<f64>)>,
}

impl Shooting<'_> {
    /// The periodic orbit of the map by semismooth Newton on the period map from `x`
    /// (the orbit on return): Newton's report, or the undecided answer (`spp` steps per
    /// period) when it could not run or did not converge; `Err` when a march failed.
    fn orbit(
        &mut self,
        x: &mut [f64],
        spp: usize,
    ) -> Result<Result<NewtonReport, MapStability>, StabilityError> {
        let scale = x.iter().fold(1.0f64, |a, v| a.max(v.abs()));
        let options = PolyalgorithmOptions {
            tolerances: semismooth::newton::Tolerances::absolute(SHOOTING_TOLERANCE * scale),
            max_iterations: 50,
            ..PolyalgorithmOptions::default()
        };
        let report = match polyalgorithm::solve(self, &mut FaerDenseLu::new(), x, &options) {
            Ok(report) => report,
            Err(err) => {
                return Ok(Err(MapStability::not_decided(
                    Undecided::ShootingNotRun(err),
                    spp,
                )))
            }
        };
        if report.converged() {
            return Ok(Ok(report));
        }
        // A march that failed inside the solve ended it and comes back in its termination.
        if let Termination::Evaluation(e) = &report.termination {
            if let Some(err) = e.downcast_ref::<StabilityError>() {
                return Err(err.clone());
            }
        }
        Ok(Err(MapStability::not_decided(
            Undecided::OrbitNotFound {
                termination: report.termination.clone(),
                iterations: report.iterations,
                residual_norm: report.residual_norms.last().copied().unwrap_or(f64::NAN),
            },
            spp,
        )))
    }

    fn state(&self, x: &[f64], contacts: usize) -> MarchState {
        let n = self.full.len() / 2;
        let mut full = self.full.clone();
        for (&i, &v) in self.keep.iter().zip(x) {
            full[i] = v;
        }
        MarchState {
            displacement: full[..n].to_vec(),
            velocity: full[n..].to_vec(),
            contact_force: vec![0.0; contacts],
        }
    }

    /// Marches one period from `x`; returns the end state on `keep`.
    fn period(&mut self, x: &[f64]) -> Result<Vec<f64>, StabilityError> {
        if let Some((last, end)) = &self.evaluated {
            if last.as_slice() == x {
                return Ok(end.clone());
            }
        }
        let contacts = self.marcher.model().contact_count();
        let state = self.state(x, contacts);
        self.marcher.restart_at(0, &state)?;
        self.runs.clear();
        let spp = self.marcher.steps_per_period();
        for _ in 0..spp {
            self.marcher.step()?;
            let forces = self.marcher.contact_force();
            // The closed contacts of this step, compared with the last run's without a new
            // set: a set is allocated only where it changes (a few times per period).
            let closed = (0..contacts).filter(|&k| forces[k] < 0.0);
            match self.runs.last_mut() {
                Some((set, count)) if set.iter().copied().eq(closed.clone()) => *count += 1,
                _ => self.runs.push((closed.collect(), 1)),
            }
        }
        let n = self.full.len() / 2;
        let end: Vec<f64> = self
            .keep
            .iter()
            .map(|&i| {
                if i < n {
                    self.marcher.displacement()[i]
                } else {
                    self.marcher.velocity()[i - n]
                }
            })
            .collect();
        self.evaluated = Some((x.to_vec(), end.clone()));
        Ok(end)
    }
}

impl Residual for Shooting<'_> {
    fn dim(&self) -> usize {
        self.keep.len()
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let end = self.period(x).map_err(EvaluationError::problem)?;
        for ((o, e), xi) in out.iter_mut().zip(&end).zip(x) {
            *o = e - xi;
        }
        Ok(())
    }
}

impl GeneralizedJacobian for Shooting<'_> {
    type Jacobian = Mat<f64>;

    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.keep.len(), self.keep.len())
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        self.period(x).map_err(EvaluationError::problem)?;
        let full = monodromy(&mut self.marcher, &self.runs).map_err(EvaluationError::problem)?;
        let keep = &self.keep;
        for (j, &cj) in keep.iter().enumerate() {
            for (i, &ci) in keep.iter().enumerate() {
                jac[(i, j)] = full[(ci, cj)] - if i == j { 1.0 } else { 0.0 };
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::{build_rod, DampingSpec, MassModel, RodSpec};

    /// Without contact the map is the trapezoidal rule on a linear system: its multipliers
    /// are `((1 + z/2) / (1 - z/2))^n_s` for each eigenvalue `z = h s` of the first-order
    /// system, i.e. `exp(s T)` up to `O(h^2)`; for Rayleigh damping `D = beta K` mode `k`
    /// has `s = -zeta_k w_k +- i w_k sqrt(1 - zeta_k^2)`, `zeta_k = beta w_k / 2`.
    #[test]
    fn linear_rod_multipliers_are_the_damped_modes() {
        let spec = RodSpec {
            elements: 6,
            mass: MassModel::Consistent,
            contacts: vec![],
            ..RodSpec::canonical()
        };
        let rod = build_rod(&spec).unwrap();
        let omega = 1.3 * rod.omega_1;
        let harmonics = 2;
        let u = vec![0.0; rod.model.dofs() * (2 * harmonics + 1)];
        let s = map_stability(
            &rod.model,
            harmonics,
            omega,
            &u,
            &StabilityOptions::default(),
        )
        .unwrap();
        let beta = match spec.damping {
            Some(DampingSpec::StiffnessProportional { zeta }) => 2.0 * zeta / rod.omega_1,
            _ => unreachable!(),
        };
        let period = 2.0 * std::f64::consts::PI / omega;
        let w1 = rod.omega_1;
        let expected = (-beta * w1 * w1 / 2.0 * period).exp();
        let got = s.floquet_max_abs.unwrap();
        assert!(
            (got - expected).abs() < 1e-6,
            "largest multiplier {got} against exp(-zeta_1 w_1 T) = {expected}"
        );
        assert_eq!(s.stable, Some(true));
        assert_eq!(s.contact_steps, 0);
    }

    #[test]
    fn massive_contact_node_is_undecided_with_a_reason() {
        let rod = build_rod(&RodSpec::canonical()).unwrap();
        let u = vec![0.0; rod.model.dofs() * 3];
        let s =
            map_stability(&rod.model, 1, rod.omega_1, &u, &StabilityOptions::default()).unwrap();
        assert_eq!(s.stable, None);
        assert_eq!(s.undecided, Some(Undecided::MassCarryingContact));
    }

    #[test]
    fn bad_input_is_an_error() {
        let rod = build_rod(&RodSpec::canonical()).unwrap();
        let u = vec![0.0; 5];
        assert!(matches!(
            map_stability(&rod.model, 1, rod.omega_1, &u, &StabilityOptions::default()),
            Err(StabilityError::Dimension { .. })
        ));
        let u = vec![0.0; rod.model.dofs() * 3];
        let bad = StabilityOptions {
            steps_per_period: 2,
        };
        assert!(matches!(
            map_stability(&rod.model, 1, rod.omega_1, &u, &bad),
            Err(StabilityError::InvalidOption {
                name: "steps_per_period",
                ..
            })
        ));
        assert!(matches!(
            map_stability(&rod.model, 1, f64::NAN, &u, &StabilityOptions::default()),
            Err(StabilityError::InvalidOption { name: "omega", .. })
        ));
    }
}
