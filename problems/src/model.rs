//! The semi-discrete structural model with unilateral contact.
//!
//! `M u'' + D u' + K u = f(t) + G^T lambda(t)`, with contact rows
//! `G u - g <= 0, lambda <= 0, (G u - g) . lambda = 0` (lambda is the force the obstacle
//! applies, non-positive: it pushes the structure back).
//!
//! [`StructuralModel::validate`] is the one check every formulation makes before using a
//! model: square matrices of one size `N >= 1`, a forcing of length `N`, finite entries, a
//! finite `omega > 0`, and contacts on existing dofs with finite gaps, at most one per dof
//! and side (two contacts on one side of a dof would make the rows of `G` equal: the
//! harmonic-balance Jacobian and the time-marching contact problem are then singular). Two
//! contacts on one dof from opposite sides are a two-sided clearance (backlash): their
//! gaps must leave room between the obstacles (sum > 0), so that at most one is closed at a
//! time.

use std::ops::{AddAssign, Mul};

use faer::sparse::{SparseColMat, SparseColMatRef};
use num_traits::Zero;
use semismooth::{Factorize, LinearSolve};

/// Sparse symmetric matrix storage used for `M`, `D` and `K` (column-compressed, faer).
pub type SparseMatrix = SparseColMat<usize, f64>;

/// One unilateral contact: the obstacle limits degree of freedom `dof` to
/// `s u[dof] - gap <= 0`, `s = direction.sign()` (+1: obstacle on the positive side, -1: on
/// the negative side). Row of `G` is `s` times the unit vector on `dof`; the force the
/// obstacle applies to the dof is `s lambda` (`lambda <= 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Index of the constrained degree of freedom (0-based among the free unknowns).
    pub dof: usize,
    /// Initial gap `g` (negative: preloaded against the obstacle at rest).
    pub gap: f64,
    /// Side of the obstacle.
    pub direction: ContactDirection,
}

impl ContactPoint {
    /// A contact with the obstacle on the positive side (`u[dof] - gap <= 0`).
    pub fn new(dof: usize, gap: f64) -> Self {
        Self {
            dof,
            gap,
            direction: ContactDirection::Positive,
        }
    }

    /// The entry `s = +-1` of the contact's row of `G`.
    pub fn sign(&self) -> f64 {
        self.direction.sign()
    }
}

/// Which side of a contact dof the obstacle is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactDirection {
    /// Obstacle on the positive side: `u[dof] - gap <= 0`.
    #[default]
    Positive,
    /// Obstacle on the negative side: `-u[dof] - gap <= 0`.
    Negative,
}

impl ContactDirection {
    /// `+1` or `-1`: the entry of the contact's row of `G`.
    pub fn sign(self) -> f64 {
        match self {
            ContactDirection::Positive => 1.0,
            ContactDirection::Negative => -1.0,
        }
    }
}

/// Periodic external force `f(t) = amplitude * cos(omega t)` (a fixed spatial shape).
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicForcing {
    /// Nodal amplitude vector (length `N`).
    pub amplitude: Vec<f64>,
    /// Angular frequency `omega` (rad per unit time); the period is `2 pi / omega`.
    pub omega: f64,
}

/// The whole semi-discrete model: only the effects it declares are present
/// (`damping = None` means no damping matrix; empty `contacts` means a linear problem).
#[derive(Debug, Clone)]
pub struct StructuralModel {
    /// Mass matrix `M` (N x N, symmetric positive semi-definite).
    pub mass: SparseMatrix,
    /// Damping matrix `D`, absent when undamped.
    pub damping: Option<SparseMatrix>,
    /// Stiffness matrix `K` (N x N, symmetric positive definite).
    pub stiffness: SparseMatrix,
    /// External periodic force.
    pub forcing: HarmonicForcing,
    /// Unilateral contacts (rows of `G` and gaps `g`).
    pub contacts: Vec<ContactPoint>,
}

/// A structure ready for every method: the model, its first finite natural frequency
/// `omega_1` (the unit of `omega_ratio` in scenes and sweeps) and the dof whose displacement
/// outputs describe (`tip_*` fields, plots): the rod's tip, or a scene's `[output] dof`.
#[derive(Debug, Clone)]
pub struct Structure {
    /// The semi-discrete model `M, D, K, f, G, g`.
    pub model: StructuralModel,
    /// First finite natural frequency (rad per unit time).
    pub omega_1: f64,
    /// The observed dof (0-based).
    pub observed_dof: usize,
}

/// Why a [`StructuralModel`] cannot be used: the part, the value found and what is allowed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum InvalidModel {
    /// The stiffness matrix has no row: there is no degree of freedom.
    #[error("the model has no degree of freedom: allowed N >= 1")]
    NoDofs,
    /// A matrix is not `N x N` (`N` the number of rows of the stiffness matrix).
    #[error("model {part} is {rows} x {cols}: allowed {dofs} x {dofs} (N x N)")]
    MatrixSize {
        /// `"stiffness matrix"`, `"mass matrix"` or `"damping matrix"`.
        part: &'static str,
        /// Rows found.
        rows: usize,
        /// Columns found.
        cols: usize,
        /// `N`.
        dofs: usize,
    },
    /// The forcing amplitude does not have one entry per dof.
    #[error("model forcing amplitude has length {found}: allowed {dofs} (one entry per dof)")]
    ForcingLength {
        /// Length found.
        found: usize,
        /// `N`.
        dofs: usize,
    },
    /// A matrix entry, a forcing entry or a gap is NaN or infinite.
    #[error("model {part} holds a non-finite value {value}: allowed finite numbers")]
    NonFinite {
        /// `"stiffness matrix"`, `"mass matrix"`, `"damping matrix"`,
        /// `"forcing amplitude"` or `"contact gap"`.
        part: &'static str,
        /// The value found.
        value: f64,
    },
    /// The forcing frequency is not a finite positive number.
    #[error("model forcing omega = {value}: allowed a finite angular frequency > 0")]
    Omega {
        /// The value found.
        value: f64,
    },
    /// A contact constrains a dof that does not exist.
    #[error("contact {contact} is on dof {dof}: allowed 0..{dofs}")]
    ContactDofOutOfRange {
        /// Index of the contact.
        contact: usize,
        /// Its dof.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
    /// Two contacts constrain the same dof from the same side.
    #[error(
        "contacts {first} and {second} are both on dof {dof}, same side: allowed one contact per \
         dof and side"
    )]
    DuplicateContactDof {
        /// The earlier contact.
        first: usize,
        /// The later contact.
        second: usize,
        /// The shared dof.
        dof: usize,
    },
    /// Two contacts on one dof from opposite sides leave no room between the obstacles.
    #[error(
        "contacts {first} and {second} on dof {dof} leave a clearance {clearance} between the \
         obstacles: allowed a sum of the two gaps > 0"
    )]
    NoClearance {
        /// The earlier contact.
        first: usize,
        /// The later contact.
        second: usize,
        /// The shared dof.
        dof: usize,
        /// The sum of the two gaps.
        clearance: f64,
    },
    /// A dof asked to be observed does not exist.
    #[error("observed dof {dof} is out of range: the model has {dofs} dofs")]
    ObservedDofOutOfRange {
        /// The dof requested.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
}

impl StructuralModel {
    /// `Err(ObservedDofOutOfRange)` for the first of `observed` that is not a dof.
    pub fn check_observed(&self, observed: &[usize]) -> Result<(), InvalidModel> {
        check_observed(observed, self.dofs())
    }
}

/// `Err(ObservedDofOutOfRange)` for the first of `observed` that is not below `dofs`.
pub(crate) fn check_observed(observed: &[usize], dofs: usize) -> Result<(), InvalidModel> {
    match observed.iter().find(|&&d| d >= dofs) {
        Some(&dof) => Err(InvalidModel::ObservedDofOutOfRange { dof, dofs }),
        None => Ok(()),
    }
}

impl StructuralModel {
    /// Checks the model (module documentation): the first defect found, with its numbers.
    pub fn validate(&self) -> Result<(), InvalidModel> {
        let n = self.dofs();
        if n == 0 {
            return Err(InvalidModel::NoDofs);
        }
        let matrices = [
            ("stiffness matrix", Some(&self.stiffness)),
            ("mass matrix", Some(&self.mass)),
            ("damping matrix", self.damping.as_ref()),
        ];
        for (part, matrix) in matrices {
            let Some(matrix) = matrix else { continue };
            let (rows, cols) = (matrix.nrows(), matrix.ncols());
            if rows != n || cols != n {
                return Err(InvalidModel::MatrixSize {
                    part,
                    rows,
                    cols,
                    dofs: n,
                });
            }
            first_non_finite(part, matrix.val())?;
        }
        let amplitude = &self.forcing.amplitude;
        if amplitude.len() != n {
            return Err(InvalidModel::ForcingLength {
                found: amplitude.len(),
                dofs: n,
            });
        }
        first_non_finite("forcing amplitude", amplitude)?;
        let omega = self.forcing.omega;
        if !(omega.is_finite() && omega > 0.0) {
            return Err(InvalidModel::Omega { value: omega });
        }
        for (contact, c) in self.contacts.iter().enumerate() {
            if c.dof >= n {
                return Err(InvalidModel::ContactDofOutOfRange {
                    contact,
                    dof: c.dof,
                    dofs: n,
                });
            }
            first_non_finite("contact gap", &[c.gap])?;
            for (first, o) in self.contacts[..contact].iter().enumerate() {
                if o.dof != c.dof {
                    continue;
                }
                if o.direction == c.direction {
                    return Err(InvalidModel::DuplicateContactDof {
                        first,
                        second: contact,
                        dof: c.dof,
                    });
                }
                let clearance = o.gap + c.gap;
                if clearance.is_nan() || clearance <= 0.0 {
                    return Err(InvalidModel::NoClearance {
                        first,
                        second: contact,
                        dof: c.dof,
                        clearance,
                    });
                }
            }
        }
        Ok(())
    }

    /// Number of degrees of freedom `N`.
    pub fn dofs(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Number of contact constraints `m`.
    pub fn contact_count(&self) -> usize {
        self.contacts.len()
    }

    /// Stiffness scale seen by the contacts: the mean of `K[dof, dof]` over the contact
    /// dofs (1 when there is no contact). It converts a length into a force and is the
    /// default for the complementarity constant `c` and the unit of penalty stiffnesses.
    pub fn contact_stiffness_scale(&self) -> f64 {
        if self.contacts.is_empty() {
            return 1.0;
        }
        let sum: f64 = self
            .contacts
            .iter()
            .map(|c| diagonal_entry(&self.stiffness, c.dof))
            .sum();
        sum / self.contacts.len() as f64
    }
}

impl StructuralModel {
    /// Static stiffness seen by the contacts: the mean over the contacts of
    /// `1 / (G K^{-1} G^T)_ii`, the force that moves contact `i` by a unit length with the
    /// rest of the structure free. Independent of the mesh (for the rod: `EA / x_node`);
    /// `None` without contacts or when `K` cannot be factored.
    pub fn static_contact_stiffness(&self) -> Option<f64> {
        if self.contacts.is_empty() {
            return None;
        }
        let mut lu = semismooth::linalg::FaerSparseLu::new();
        lu.factor(&self.stiffness).ok()?;
        let mut rhs = vec![0.0; self.dofs()];
        let mut compliances = Vec::with_capacity(self.contacts.len());
        for c in &self.contacts {
            rhs.fill(0.0);
            rhs[c.dof] = 1.0;
            lu.solve_in_place(&mut rhs).ok()?;
            compliances.push(rhs[c.dof]);
        }
        mean_stiffness(compliances)
    }

    /// Default complementarity constant `c` of SSN-HB: ten times the static contact
    /// stiffness (the contact stiffness scale when `K` cannot be factored).
    ///
    /// `c` converts a length into a force. Measured on the canonical rod (H = 20): with
    /// `c` between 1 and 30 times the static stiffness Newton converges from zero in 7-14
    /// iterations for 20 to 100,000 elements, and 10 gives the smallest truncation error;
    /// the local stiffness `K[tip, tip] = EA/h` grows with the mesh and from 200 elements on
    /// Newton no longer converges with it.
    pub fn default_complementarity_constant(&self) -> f64 {
        self.static_contact_stiffness()
            .map(|k| DEFAULT_C_FACTOR * k)
            .unwrap_or_else(|| self.contact_stiffness_scale())
    }
}

/// Ratio of the default complementarity constant `c` to the static contact stiffness.
pub const DEFAULT_C_FACTOR: f64 = 10.0;

/// Entry `(i, i)` of a column-compressed matrix (0 when not stored).
pub fn diagonal_entry(matrix: &SparseMatrix, i: usize) -> f64 {
    semismooth::linalg::diagonal_entry(matrix.as_ref(), i).unwrap_or(0.0)
}

/// `Err(NonFinite)` with the first NaN or infinite entry of `values`.
fn first_non_finite(part: &'static str, values: &[f64]) -> Result<(), InvalidModel> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(InvalidModel::NonFinite { part, value }),
        None => Ok(()),
    }
}

/// The mean of `1 / compliance` over the contacts' static compliances `(G K^{-1} G^T)_ii`:
/// the static contact stiffness. `None` without contacts or when a compliance is not a
/// finite positive number (`K` not positive definite).
pub(crate) fn mean_stiffness(compliances: impl IntoIterator<Item = f64>) -> Option<f64> {
    let (mut count, mut sum) = (0usize, 0.0);
    for c in compliances {
        if !(c.is_finite() && c > 0.0) {
            return None;
        }
        count += 1;
        sum += 1.0 / c;
    }
    (count > 0).then(|| sum / count as f64)
}

/// `y += alpha A x` for a column-compressed `A` (`x` of length `ncols`, `y` of length
/// `nrows`), real or complex. Columns whose `alpha x_j` is zero are skipped.
pub(crate) fn sparse_mul_add<T>(a: SparseColMatRef<'_, usize, T>, alpha: T, x: &[T], y: &mut [T])
where
    T: Copy + Zero + Mul<Output = T> + AddAssign,
{
    for (j, &xj) in x.iter().enumerate().take(a.ncols()) {
        let scaled = alpha * xj;
        if scaled.is_zero() {
            continue;
        }
        for (i, &v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            y[i] += v * scaled;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// A valid 3-dof chain with one contact on the last dof.
    fn chain() -> StructuralModel {
        let matrix = |d: f64, o: f64| {
            let mut t = Vec::new();
            for i in 0..3 {
                t.push(Triplet::new(i, i, d));
                if i + 1 < 3 {
                    t.push(Triplet::new(i, i + 1, o));
                    t.push(Triplet::new(i + 1, i, o));
                }
            }
            SparseMatrix::try_new_from_triplets(3, 3, &t).unwrap()
        };
        StructuralModel {
            mass: matrix(2.0, 0.5),
            damping: Some(matrix(0.2, -0.1)),
            stiffness: matrix(2.0, -1.0),
            forcing: HarmonicForcing {
                amplitude: vec![0.0, 0.0, 1.0],
                omega: 1.0,
            },
            contacts: vec![ContactPoint::new(2, 0.1)],
        }
    }

    #[test]
    fn validate_names_the_part_and_the_numbers() {
        assert_eq!(chain().validate(), Ok(()));
        let mut m = chain();
        m.mass = SparseMatrix::try_new_from_triplets(3, 2, &[]).unwrap();
        assert_eq!(
            m.validate(),
            Err(InvalidModel::MatrixSize {
                part: "mass matrix",
                rows: 3,
                cols: 2,
                dofs: 3
            })
        );
        let mut m = chain();
        m.forcing.amplitude.push(0.0);
        assert_eq!(
            m.validate(),
            Err(InvalidModel::ForcingLength { found: 4, dofs: 3 })
        );
        let mut m = chain();
        m.forcing.amplitude[1] = f64::INFINITY;
        assert_eq!(
            m.validate(),
            Err(InvalidModel::NonFinite {
                part: "forcing amplitude",
                value: f64::INFINITY
            })
        );
        let mut m = chain();
        m.forcing.omega = -1.0;
        assert_eq!(m.validate(), Err(InvalidModel::Omega { value: -1.0 }));
        let mut m = chain();
        m.contacts.push(ContactPoint::new(3, 0.0));
        assert_eq!(
            m.validate(),
            Err(InvalidModel::ContactDofOutOfRange {
                contact: 1,
                dof: 3,
                dofs: 3
            })
        );
        let mut m = chain();
        m.contacts.push(ContactPoint::new(0, 0.0));
        m.contacts.push(ContactPoint::new(2, 0.3));
        assert_eq!(
            m.validate(),
            Err(InvalidModel::DuplicateContactDof {
                first: 0,
                second: 2,
                dof: 2
            })
        );
        let mut m = chain();
        m.contacts[0].gap = f64::NAN;
        assert!(matches!(
            m.validate(),
            Err(InvalidModel::NonFinite { part: "contact gap", value }) if value.is_nan()
        ));
        let mut m = chain();
        m.stiffness = SparseMatrix::try_new_from_triplets(0, 0, &[]).unwrap();
        assert_eq!(m.validate(), Err(InvalidModel::NoDofs));
        let mut m = chain();
        m.forcing.omega = 0.0;
        let message = m.validate().unwrap_err().to_string();
        assert!(
            message.contains("omega = 0") && message.contains("allowed"),
            "{message}"
        );
    }

    #[test]
    fn sparse_mul_add_matches_the_dense_product() {
        let m = chain();
        let k = m.stiffness.as_ref();
        let x = [1.0, -2.0, 0.5];
        let mut y = [1.0, 1.0, 1.0];
        sparse_mul_add(k, 2.0, &x, &mut y);
        // K x = [2 + 2, -1 - 4 - 0.5, 2 + 1] = [4, -5.5, 3].
        assert_eq!(y, [9.0, -10.0, 7.0]);
        let xc: Vec<faer::c64> = x.iter().map(|v| faer::c64::new(0.0, *v)).collect();
        let mut yc = vec![faer::c64::new(0.0, 0.0); 3];
        let kc = SparseColMat::<usize, faer::c64>::try_new_from_triplets(
            3,
            3,
            &[Triplet::new(0, 0, faer::c64::new(1.0, 1.0))],
        )
        .unwrap();
        sparse_mul_add(kc.as_ref(), faer::c64::new(1.0, 0.0), &xc, &mut yc);
        // (1 + i) * i = -1 + i.
        assert_eq!(yc[0], faer::c64::new(-1.0, 1.0));
    }

    #[test]
    fn static_stiffness_is_the_mean_inverse_compliance() {
        assert_eq!(mean_stiffness([]), None);
        assert_eq!(mean_stiffness([0.5, 0.25]), Some(3.0));
        assert_eq!(mean_stiffness([0.5, -1.0]), None);
        // K = tridiag(-1, 2, -1) on 3 dofs: (K^-1)_22 = 3/4.
        let k = chain().static_contact_stiffness().unwrap();
        assert!((k - 4.0 / 3.0).abs() < 1e-14, "{k}");
    }
}
