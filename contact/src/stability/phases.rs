//! The linear dynamics of a perturbation during each contact phase of a periodic orbit,
//! their exact propagators, and the saltation at the closing of a contact.
//!
//! # One phase
//!
//! With the set `A` of closed contacts fixed, a perturbation `(dq, dv)` of the orbit obeys
//! `M dq'' + D dq' + K_A dq = 0` on the free dofs, where
//!
//! - with the Signorini law (SSN-HB) the dofs of closed contacts are held
//!   (`dq = dv = 0`: the contact stays closed, the perturbation moves with the orbit), and
//!   `K_A = K` on the others;
//! - with a penalty law `K_A = K + k_p sum_{i in A} e_i e_i^T` and nothing is held.
//!
//! Among the free dofs, those with mass (`a`) carry `(dq_a, dv_a)`; the massless ones
//! (zero column of `M`) follow the others: statically (`K_ua dq_a + K_uu dq_u = 0`) when
//! the damping rows of the massless dofs vanish, or by first-order dynamics
//! (`D_ba dv_a + D_bb dq_b' + K_b. dq = 0`, `D_bb` nonsingular, e.g. stiffness-proportional
//! damping) otherwise. The phase's state `y = (dq_a, dq_b, dv_a)` then obeys `y' = S_A y`
//! with a constant matrix, and its propagator over a time `tau` is `exp(S_A tau)`, computed
//! from the eigendecomposition of `S_A` (made once per phase and reused for every
//! duration), or by Padé scaling and squaring (nalgebra) when the eigenvectors are
//! ill-conditioned.
//!
//! # Closing a contact (saltation)
//!
//! When contact `c` closes at an instant `t*` with approach speed `s_c q_c'(t*-) != 0`, a
//! perturbation shifts the instant by `-dq_c / q_c'` and the jump of the vector field
//! enters the perturbation (the saltation matrix `S = D_g + (f+ - D_g f-) n^T / (n^T f-)`,
//! `n = e_{q_c}`, Müller 1995, Leine & Nijmeijer 2004). With a held dof the jump of `f` is
//! proportional to the approach speed, which cancels: the saltation depends on the model
//! only, not on the orbit.
//!
//! - Dof with mass, perfectly inelastic impact (restitution 0: the dof stays on the
//!   obstacle; the only impact law under which a closed interval of positive length
//!   follows an arrival with nonzero speed): `w = M_aa^{-1} e_c / (M_aa^{-1})_cc`,
//!   `dq_a+ = dq_a - w dq_c`, `dv_a+ = P (dv_a + M_aa^{-1} D_eff w dq_c)`, `P = I - w e_c^T`,
//!   `dq_b+ = dq_b + D_bb^{-1} D_ba w dq_c`, with `D_eff = D_aa - D_ab D_bb^{-1} D_ba`.
//! - Massless dof with first-order dynamics: `dq_c+ = 0`,
//!   `dq_b'+ = dq_b' + D_b'b'^{-1} D_b'c dq_c`,
//!   `dv_a+ = dv_a + M_aa^{-1} (D_ac - D_ab' D_b'b'^{-1} D_b'c) dq_c` (`b' = b \ c`).
//! - Massless dof following statically: nothing jumps (the vector field of the others is
//!   continuous); the held dof is simply not a state of the next phase.
//!
//! An orbit that rebounds ([`PhaseModel::rebound`]): an impact with restitution `e`
//! followed by free flight, `v+ = P_e v-`, `P_e = I - (1 + e) w e_c^T`; the vector field
//! after it is the free one, so the saltation keeps the term `(1 + e) w a_c / v_c` of the
//! contact dof's free acceleration `a_c` over its approach speed `v_c`.
//!
//! At an opening the force returns to zero continuously: nothing jumps, the released dof
//! enters the next phase with `dq = dv = 0`. A penalty law has a continuous vector field:
//! no saltation at all.

use std::collections::HashMap;

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{c64, Mat};

use crate::model::{HarmonicLoad, SparseMatrix, StructuralModel};

/// Relative pivot below which a block that must be inverted is singular.
const SINGULAR_PIVOT: f64 = 1e-12;

/// Largest relative error `|U diag(l) U^-1 - S| / |S|` of an eigendecomposition used for
/// the propagators; above it the propagators are computed by Padé scaling and squaring.
const EIGEN_RECONSTRUCTION: f64 = 1e-9;

/// How a closed contact acts on the perturbation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ClosedContact {
    /// The contact's dof is held (Signorini law, SSN-HB).
    Held,
    /// A penalty spring of this stiffness acts on the contact's dof (penalty HB).
    Spring(f64),
}

/// Why the phases of an orbit cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PhaseError {
    /// A block that the elimination of the massless dofs inverts is singular.
    #[error(
        "the {block} block of a contact phase is singular (pivot {pivot:e} against {max_pivot:e})"
    )]
    SingularBlock {
        /// `"damping (massless dofs)"`, `"stiffness (massless dofs)"` or `"mass"`.
        block: &'static str,
        /// The smallest pivot.
        pivot: f64,
        /// The largest pivot.
        max_pivot: f64,
    },
    /// The eigendecomposition of a phase's system matrix failed.
    #[error("the eigenvalues of a {size} x {size} phase matrix did not converge")]
    Eigen {
        /// Its size.
        size: usize,
    },
}

/// The model as dense matrices, and the cache of the phases met so far (keyed by the set
/// of closed contacts).
pub(crate) struct PhaseModel {
    n: usize,
    stiffness: Mat<f64>,
    damping: Option<Mat<f64>>,
    mass: Mat<f64>,
    massless: Vec<bool>,
    /// Whether the massless dofs follow by first-order dynamics (a damping entry on a
    /// massless row) rather than statically.
    first_order_massless: bool,
    contact_dofs: Vec<usize>,
    /// The load's spatial shape (`f(t) = load cos(omega t)`).
    load: HarmonicLoad,
    closed: ClosedContact,
    phases: HashMap<Vec<usize>, Phase>,
}

/// One contact phase (module documentation).
pub(crate) struct Phase {
    /// Free dofs with mass.
    pub(crate) massive: Vec<usize>,
    /// Free massless dofs with first-order dynamics.
    pub(crate) first_order: Vec<usize>,
    /// Free massless dofs following statically.
    statics_dofs: Vec<usize>,
    /// `dq_u = statics (dq_a; dq_b)`.
    statics: Mat<f64>,
    /// `S_A` on `y = (dq_a, dq_b, dv_a)`.
    system: Mat<f64>,
    exponential: Exponential,
    /// Saltation matrices of the closings from this phase, by contact.
    closings: HashMap<usize, Mat<f64>>,
    /// `M_aa` (for the saltations).
    mass_aa: Mat<f64>,
}

enum Exponential {
    /// `S = U diag(l) U^{-1}`.
    Eigen {
        vectors: Mat<c64>,
        values: Vec<c64>,
        inverse: Mat<c64>,
    },
    /// Padé scaling and squaring at each duration.
    Pade,
}

fn dense(matrix: &SparseMatrix) -> Mat<f64> {
    let a = matrix.as_ref();
    let mut out = Mat::zeros(a.nrows(), a.ncols());
    for j in 0..a.ncols() {
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            out[(i, j)] += *v;
        }
    }
    out
}

fn block(a: &Mat<f64>, rows: &[usize], cols: &[usize]) -> Mat<f64> {
    Mat::from_fn(rows.len(), cols.len(), |i, j| a[(rows[i], cols[j])])
}

/// `a^{-1} b` with a pivot check (`block` names `a` in the error).
fn solve(a: &Mat<f64>, b: &Mat<f64>, block: &'static str) -> Result<Mat<f64>, PhaseError> {
    if a.nrows() == 0 {
        return Ok(Mat::zeros(0, b.ncols()));
    }
    let lu = PartialPivLu::new(a.as_ref());
    let u = lu.U();
    let (mut min, mut max) = (f64::INFINITY, 0.0f64);
    for i in 0..u.nrows() {
        let p = u[(i, i)].abs();
        min = min.min(p);
        max = max.max(p);
    }
    if min.is_nan() || min <= SINGULAR_PIVOT * max {
        return Err(PhaseError::SingularBlock {
            block,
            pivot: min,
            max_pivot: max,
        });
    }
    let mut x = b.clone();
    lu.solve_in_place(x.as_mut());
    Ok(x)
}

impl PhaseModel {
    /// The dense model (`N` dofs; the caller limits `N`) with closed contacts acting as
    /// `closed`.
    pub(crate) fn new(model: &StructuralModel, closed: ClosedContact) -> Self {
        let n = model.dofs();
        let mass = dense(&model.mass);
        let massless: Vec<bool> = (0..n)
            .map(|j| (0..n).all(|i| mass[(i, j)] == 0.0))
            .collect();
        let damping = model.damping.as_ref().map(dense);
        let first_order_massless = damping
            .as_ref()
            .is_some_and(|d| (0..n).any(|i| massless[i] && (0..n).any(|j| d[(i, j)] != 0.0)));
        Self {
            n,
            stiffness: dense(&model.stiffness),
            damping,
            mass,
            massless,
            first_order_massless,
            contact_dofs: model.contacts.iter().map(|c| c.dof()).collect(),
            load: model.load.clone(),
            closed,
            phases: HashMap::new(),
        }
    }

    /// The phase with the contacts `closed` (sorted indices) closed, built on first use.
    pub(crate) fn phase(&mut self, closed: &[usize]) -> Result<&mut Phase, PhaseError> {
        if !self.phases.contains_key(closed) {
            let phase = self.build(closed)?;
            self.phases.insert(closed.to_vec(), phase);
        }
        Ok(self.phases.get_mut(closed).expect("inserted"))
    }

    /// The matrix taking a state of the phase `from` to the phase `to`
    /// ([`Phase::transfer_to`]).
    pub(crate) fn transfer(
        &mut self,
        from: &[usize],
        to: &[usize],
    ) -> Result<Mat<f64>, PhaseError> {
        self.phase(from)?;
        self.phase(to)?;
        Ok(self.phases[from].transfer_to(&self.phases[to]))
    }

    /// Whether the phase with the contacts `closed` closed is built.
    pub(crate) fn has_phase(&self, closed: &[usize]) -> bool {
        self.phases.contains_key(closed)
    }

    /// Whether contact `contact` holds a dof with mass (the closings of such a contact are
    /// impacts).
    pub(crate) fn impacts(&self, contact: usize) -> bool {
        self.closed == ClosedContact::Held && !self.massless[self.contact_dofs[contact]]
    }

    /// The saltation (on the coordinates of the phase `pre`) of an impact of contact
    /// `contact` with restitution `e` followed by free flight, at the orbit's state
    /// `(q, v)` just before it with the load's phase `omega t = load_phase`:
    /// `dq+ = dq - (1 + e) w dq_c`, `dv+ = P_e dv + (1 + e) (M^{-1} D_eff w + w a_c / v_c) dq_c`,
    /// `P_e = I - (1 + e) w e_c^T` (module documentation). `None` when the dof is not a
    /// massive dof of `pre` or `pre` has first-order massless dofs.
    pub(crate) fn rebound(
        &mut self,
        pre: &[usize],
        contact: usize,
        restitution: f64,
        (q, v): (&[f64], &[f64]),
        load_phase: f64,
    ) -> Result<Option<Mat<f64>>, PhaseError> {
        let dof = self.contact_dofs[contact];
        let n = self.n;
        // Free acceleration of the massive dofs: M_aa a = f_a - (K q)_a - (D v)_a.
        let mut load = vec![0.0; n];
        self.load.at_phase(load_phase, &mut load);
        let force: Vec<f64> = (0..n)
            .map(|i| {
                let mut f = load[i];
                for j in 0..n {
                    f -= self.stiffness[(i, j)] * q[j];
                    if let Some(d) = &self.damping {
                        f -= d[(i, j)] * v[j];
                    }
                }
                f
            })
            .collect();
        let zero = Mat::zeros(0, 0);
        let damping = self.damping.clone().unwrap_or(zero);
        let phase = self.phase(pre)?;
        let Some(ic) = phase.massive.iter().position(|&j| j == dof) else {
            return Ok(None);
        };
        let (na, nb) = (phase.massive.len(), phase.first_order.len());
        if nb > 0 || v[dof] == 0.0 {
            return Ok(None);
        }
        let rhs = Mat::from_fn(na, 1, |i, _| force[phase.massive[i]]);
        let acceleration = solve(&phase.mass_aa, &rhs, "mass")?;
        let ratio = acceleration[(ic, 0)] / v[dof];
        let ImpulseResponse { w, v_kick, .. } = impulse_response(phase, &damping, ic)?;
        let gain = 1.0 + restitution;
        let mut s = Mat::<f64>::identity(2 * na, 2 * na);
        for i in 0..na {
            s[(i, ic)] -= gain * w[(i, 0)];
            s[(na + i, na + ic)] -= gain * w[(i, 0)];
            s[(na + i, ic)] += gain * (v_kick[(i, 0)] + w[(i, 0)] * ratio);
        }
        Ok(Some(s))
    }

    /// Whether the massless dofs follow by first-order dynamics.
    pub(crate) fn first_order_massless(&self) -> bool {
        self.first_order_massless
    }

    /// Number of dofs.
    pub(crate) fn dofs(&self) -> usize {
        self.n
    }

    /// The dofs held with the contacts `closed` closed (none for a penalty law).
    fn held(&self, closed: &[usize]) -> Vec<usize> {
        match self.closed {
            ClosedContact::Spring(_) => Vec::new(),
            ClosedContact::Held => {
                let mut dofs: Vec<usize> = closed.iter().map(|&i| self.contact_dofs[i]).collect();
                dofs.sort_unstable();
                dofs.dedup();
                dofs
            }
        }
    }

    fn build(&self, closed: &[usize]) -> Result<Phase, PhaseError> {
        let held = self.held(closed);
        let mut stiffness = self.stiffness.clone();
        if let ClosedContact::Spring(k) = self.closed {
            for &i in closed {
                let d = self.contact_dofs[i];
                stiffness[(d, d)] += k;
            }
        }
        let free = (0..self.n).filter(|j| held.binary_search(j).is_err());
        let (mut a, mut b, mut u) = (Vec::new(), Vec::new(), Vec::new());
        for j in free {
            if !self.massless[j] {
                a.push(j);
            } else if self.first_order_massless {
                b.push(j);
            } else {
                u.push(j);
            }
        }
        let (na, nb) = (a.len(), b.len());
        let zero = Mat::zeros(self.n, self.n);
        let damping = self.damping.as_ref().unwrap_or(&zero);
        let mass_aa = block(&self.mass, &a, &a);
        // The massive rows: M_aa v' = -(K_a. q + D_a. q'), with q_b' from the first-order
        // rows or q_u from the static ones.
        let (k_qa, k_qb, d_va, statics) = if nb > 0 {
            // q_b' = -D_bb^{-1} (K_ba q_a + K_bb q_b + D_ba v_a).
            let d_bb = block(damping, &b, &b);
            let rhs = {
                let (k_ba, k_bb, d_ba) = (
                    block(&stiffness, &b, &a),
                    block(&stiffness, &b, &b),
                    block(damping, &b, &a),
                );
                Mat::from_fn(nb, na + nb + na, |i, j| {
                    if j < na {
                        k_ba[(i, j)]
                    } else if j < na + nb {
                        k_bb[(i, j - na)]
                    } else {
                        d_ba[(i, j - na - nb)]
                    }
                })
            };
            let qb_rate = solve(&d_bb, &rhs, "damping (massless dofs)")? * -1.0;
            let d_ab = block(damping, &a, &b);
            let coupled = &d_ab * &qb_rate;
            let k_aa = block(&stiffness, &a, &a);
            let k_ab = block(&stiffness, &a, &b);
            let d_aa = block(damping, &a, &a);
            let k_qa = Mat::from_fn(na, na, |i, j| k_aa[(i, j)] + coupled[(i, j)]);
            let k_qb = Mat::from_fn(na, nb, |i, j| k_ab[(i, j)] + coupled[(i, na + j)]);
            let d_va = Mat::from_fn(na, na, |i, j| d_aa[(i, j)] + coupled[(i, na + nb + j)]);
            (k_qa, k_qb, d_va, (Mat::zeros(0, na + nb), Some(qb_rate)))
        } else {
            // q_u = -K_uu^{-1} K_ua q_a.
            let k_uu = block(&stiffness, &u, &u);
            let k_ua = block(&stiffness, &u, &a);
            let static_map = solve(&k_uu, &k_ua, "stiffness (massless dofs)")? * -1.0;
            let k_au = block(&stiffness, &a, &u);
            let d_au = block(damping, &a, &u);
            let k_qa = block(&stiffness, &a, &a) + &k_au * &static_map;
            let d_va = block(damping, &a, &a) + &d_au * &static_map;
            (k_qa, Mat::zeros(na, 0), d_va, (static_map, None))
        };
        let (static_map, qb_rate) = statics;
        let d = 2 * na + nb;
        let mut system = Mat::<f64>::zeros(d, d);
        for i in 0..na {
            system[(i, na + nb + i)] = 1.0;
        }
        if let Some(rate) = &qb_rate {
            for i in 0..nb {
                for j in 0..d {
                    system[(na + i, j)] = rate[(i, j)];
                }
            }
        }
        if na > 0 {
            let rhs = Mat::from_fn(na, d, |i, j| {
                -if j < na {
                    k_qa[(i, j)]
                } else if j < na + nb {
                    k_qb[(i, j - na)]
                } else {
                    d_va[(i, j - na - nb)]
                }
            });
            let acceleration = solve(&mass_aa, &rhs, "mass")?;
            for i in 0..na {
                for j in 0..d {
                    system[(na + nb + i, j)] = acceleration[(i, j)];
                }
            }
        }
        let exponential = Exponential::of(&system)?;
        Ok(Phase {
            massive: a,
            first_order: b,
            statics_dofs: u,
            statics: static_map,
            system,
            exponential,
            closings: HashMap::new(),
            mass_aa,
        })
    }

    /// The saltation matrix (on the coordinates of the phase `pre`) of the closing of
    /// contact `contact` from the phase with the contacts `pre` closed (module
    /// documentation); the identity for a penalty law and for a held massless dof that
    /// follows statically.
    pub(crate) fn saltation(
        &mut self,
        pre: &[usize],
        contact: usize,
    ) -> Result<Mat<f64>, PhaseError> {
        let dof = self.contact_dofs[contact];
        let damping = self.damping.clone();
        let closed = self.closed;
        let phase = self.phase(pre)?;
        if let Some(s) = phase.closings.get(&contact) {
            return Ok(s.clone());
        }
        let d = phase.dim();
        let mut s = Mat::<f64>::identity(d, d);
        let (na, nb) = (phase.massive.len(), phase.first_order.len());
        let zero = Mat::zeros(0, 0);
        let damping = damping.as_ref().unwrap_or(&zero);
        let damp = |rows: &[usize], cols: &[usize]| {
            if damping.nrows() == 0 {
                Mat::zeros(rows.len(), cols.len())
            } else {
                block(damping, rows, cols)
            }
        };
        if closed == ClosedContact::Held {
            if let Some(ic) = phase.massive.iter().position(|&j| j == dof) {
                let ImpulseResponse { w, v_kick, qb_jump } = impulse_response(phase, damping, ic)?;
                // dq_a -= w dq_c.
                for i in 0..na {
                    s[(i, ic)] -= w[(i, 0)];
                }
                // dq_b += D_bb^{-1} D_ba w dq_c.
                for i in 0..nb {
                    s[(na + i, ic)] += qb_jump[(i, 0)];
                }
                // dv_a+ = P dv_a + P M^{-1} D_eff w dq_c, P = I - w e_c^T.
                let v0 = na + nb;
                for i in 0..na {
                    s[(v0 + i, v0 + ic)] -= w[(i, 0)];
                    s[(v0 + i, ic)] += v_kick[(i, 0)] - w[(i, 0)] * v_kick[(ic, 0)];
                }
            } else if let Some(ic) = phase.first_order.iter().position(|&j| j == dof) {
                let a = phase.massive.clone();
                let rest: Vec<usize> = phase
                    .first_order
                    .iter()
                    .copied()
                    .filter(|&j| j != dof)
                    .collect();
                let d_rc = damp(&rest, &[dof]);
                let qb_jump = solve(&damp(&rest, &rest), &d_rc, "damping (massless dofs)")?;
                let d_ac = damp(&a, &[dof]);
                let kick = d_ac - &damp(&a, &rest) * &qb_jump;
                let v_kick = solve(&phase.mass_aa, &kick, "mass")?;
                let col = na + ic;
                for (r, &j) in rest.iter().enumerate() {
                    let i = phase
                        .first_order
                        .iter()
                        .position(|&k| k == j)
                        .expect("in b");
                    s[(na + i, col)] += qb_jump[(r, 0)];
                }
                for i in 0..na {
                    s[(na + nb + i, col)] += v_kick[(i, 0)];
                }
                // dq_c+ = 0.
                for j in 0..d {
                    s[(col, j)] = 0.0;
                }
            }
        }
        let phase = self.phase(pre)?;
        phase.closings.insert(contact, s.clone());
        Ok(s)
    }
}

/// What an impulse on the massive dof `massive[ic]` of a phase changes (columns).
struct ImpulseResponse {
    /// `w = M_aa^{-1} e_c / (M_aa^{-1})_cc`: the velocity change per unit change of the
    /// contact dof's velocity.
    w: Mat<f64>,
    /// `M_aa^{-1} D_eff w`: the acceleration change per unit velocity change along `w`.
    v_kick: Mat<f64>,
    /// `D_bb^{-1} D_ba w`: the jump of the first-order massless dofs.
    qb_jump: Mat<f64>,
}

/// The [`ImpulseResponse`] of the massive dof `massive[ic]` of `phase`.
fn impulse_response(
    phase: &Phase,
    damping: &Mat<f64>,
    ic: usize,
) -> Result<ImpulseResponse, PhaseError> {
    let (na, nb) = (phase.massive.len(), phase.first_order.len());
    let damp = |rows: &[usize], cols: &[usize]| {
        if damping.nrows() == 0 {
            Mat::zeros(rows.len(), cols.len())
        } else {
            block(damping, rows, cols)
        }
    };
    let (a, b) = (&phase.massive, &phase.first_order);
    let unit = Mat::from_fn(na, 1, |i, _| if i == ic { 1.0 } else { 0.0 });
    let z = solve(&phase.mass_aa, &unit, "mass")?;
    let w = Mat::from_fn(na, 1, |i, _| z[(i, 0)] / z[(ic, 0)]);
    // D_eff w, with D_eff = D_aa - D_ab D_bb^{-1} D_ba (first-order massless dofs) or
    // D_aa + D_au Q (static ones, q_u = Q q_a).
    let mut d_eff_w = &damp(a, a) * &w;
    let mut qb_jump = Mat::zeros(nb, 1);
    if nb == 0 && !phase.statics_dofs.is_empty() {
        d_eff_w += &damp(a, &phase.statics_dofs) * (&phase.statics * &w);
    }
    if nb > 0 {
        let d_ba_w = &damp(b, a) * &w;
        qb_jump = solve(&damp(b, b), &d_ba_w, "damping (massless dofs)")?;
        d_eff_w -= &damp(a, b) * &qb_jump;
    }
    let v_kick = solve(&phase.mass_aa, &d_eff_w, "mass")?;
    Ok(ImpulseResponse { w, v_kick, qb_jump })
}

impl Exponential {
    fn of(system: &Mat<f64>) -> Result<Self, PhaseError> {
        let d = system.nrows();
        if d == 0 {
            return Ok(Self::Pade);
        }
        let eigen = system.eigen().map_err(|_| PhaseError::Eigen { size: d })?;
        let vectors = eigen.U().to_owned();
        let values: Vec<c64> = (0..d).map(|i| eigen.S()[i]).collect();
        let lu = PartialPivLu::new(vectors.as_ref());
        let mut inverse = Mat::<c64>::identity(d, d);
        lu.solve_in_place(inverse.as_mut());
        let scaled = Mat::from_fn(d, d, |i, j| vectors[(i, j)] * values[j]);
        let rebuilt = &scaled * &inverse;
        let scale = system.norm_max().max(f64::MIN_POSITIVE);
        let mut error = 0.0f64;
        for j in 0..d {
            for i in 0..d {
                let e = rebuilt[(i, j)] - c64::new(system[(i, j)], 0.0);
                error = error.max(e.norm());
            }
        }
        if error.is_finite() && error <= EIGEN_RECONSTRUCTION * scale {
            Ok(Self::Eigen {
                vectors,
                values,
                inverse,
            })
        } else {
            Ok(Self::Pade)
        }
    }
}

impl Phase {
    /// Dimension of the phase's state `(dq_a, dq_b, dv_a)`.
    pub(crate) fn dim(&self) -> usize {
        2 * self.massive.len() + self.first_order.len()
    }

    /// `exp(S_A tau)`.
    pub(crate) fn propagator(&self, tau: f64) -> Mat<f64> {
        let d = self.dim();
        match &self.exponential {
            Exponential::Eigen {
                vectors,
                values,
                inverse,
            } => {
                let growth: Vec<c64> = values.iter().map(|l| (l * tau).exp()).collect();
                let scaled = Mat::from_fn(d, d, |i, j| vectors[(i, j)] * growth[j]);
                let product = &scaled * inverse;
                Mat::from_fn(d, d, |i, j| product[(i, j)].re)
            }
            Exponential::Pade => {
                let s = nalgebra::DMatrix::from_fn(d, d, |i, j| self.system[(i, j)] * tau);
                let e = s.exp();
                Mat::from_fn(d, d, |i, j| e[(i, j)])
            }
        }
    }

    /// The eigenvalues of `exp(S_A tau)`, without forming it when the eigendecomposition
    /// is at hand: `exp(l tau)`.
    pub(crate) fn propagator_eigenvalues(&self, tau: f64) -> Option<Vec<(f64, f64)>> {
        match &self.exponential {
            Exponential::Eigen { values, .. } => Some(
                values
                    .iter()
                    .map(|l| {
                        let e = (l * tau).exp();
                        (e.re, e.im)
                    })
                    .collect(),
            ),
            Exponential::Pade => None,
        }
    }

    /// The matrix taking a state of this phase to the state of `next` (components of dofs
    /// held here start at 0 in `next`; dofs held in `next` are dropped).
    pub(crate) fn transfer_to(&self, next: &Phase) -> Mat<f64> {
        let (na, nb) = (self.massive.len(), self.first_order.len());
        let (ma, mb) = (next.massive.len(), next.first_order.len());
        let mut t = Mat::<f64>::zeros(next.dim(), self.dim());
        for (i, dof) in next.massive.iter().enumerate() {
            if let Some(j) = self.massive.iter().position(|d| d == dof) {
                t[(i, j)] = 1.0;
                t[(ma + mb + i, na + nb + j)] = 1.0;
            }
        }
        for (i, dof) in next.first_order.iter().enumerate() {
            if let Some(j) = self.first_order.iter().position(|d| d == dof) {
                t[(ma + i, na + j)] = 1.0;
            }
        }
        t
    }
}
