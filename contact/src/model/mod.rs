//! The semi-discrete structural model with unilateral contact.
//!
//! `M u'' + D u' + K u = f(t) + G^T lambda(t)`, with contact rows
//! `G u - g <= 0, lambda <= 0, (G u - g) . lambda = 0` (lambda is the force the obstacle
//! applies, non-positive: it pushes the structure back).
//!
//! The external force `f(t)` is a [`HarmonicLoad`] on harmonics of the forcing frequency
//! `omega` (classically `load cos(omega t)`, [`HarmonicLoad::cosine`]): the model holds its
//! spatial parts, and every formulation takes the angular frequency `omega` as an argument
//! where it is built (and checks it: finite and `> 0`), so that one model serves every
//! frequency of a sweep without being copied.
//!
//! [`StructuralModel::validate`] is the one check every formulation makes before using a
//! model: square matrices of one size `N >= 1`, a load of length `N`, finite entries, and
//! contacts on existing dofs with finite gaps, at most one per dof and side (two contacts on one side of a dof would make the rows of `G` equal: the
//! harmonic-balance Jacobian and the time-marching contact problem are then singular). Two
//! contacts on one dof from opposite sides are a two-sided clearance (backlash): their
//! gaps must leave room between the obstacles (sum > 0), so that at most one is closed at a
//! time.

use std::ops::{AddAssign, Mul};

use faer::sparse::{SparseColMat, SparseColMatRef};
use num_traits::Zero;
use semismooth::{Factorize, InvalidOption, LinearSolve};

mod contact;
mod coupling;
mod frictional;
mod load;

pub use contact::{
    ContactDirection, ContactPoint, ContactRow, FrictionPoint, InvalidRow, NormalForce,
};
pub use coupling::{CouplingSource, CouplingTerm, CyclicCoupling, NeighbourRow};
pub use frictional::{FrictionalContact, NormalLaw};
pub use load::{HarmonicLoad, LoadHarmonic};

/// Sparse symmetric matrix storage used for `M`, `D` and `K` (column-compressed, faer).
pub type SparseMatrix = SparseColMat<usize, f64>;

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
    /// The external force `f(t)` on harmonics of the forcing frequency `omega` (today's
    /// `load cos(omega t)` is [`HarmonicLoad::cosine`]); `omega` is an argument of each
    /// formulation.
    pub load: HarmonicLoad,
    /// Unilateral contacts (rows of `G` and gaps `g`).
    pub contacts: Vec<ContactPoint>,
    /// Coulomb friction points (tangential rows of `G`, each under a contact's normal
    /// force or a prescribed normal load); empty: frictionless.
    pub friction: Vec<FrictionPoint>,
    /// The phase-shifted interface couplings of a reduced cyclic sector
    /// ([`crate::cyclic::CyclicSector`]); `None` for every other model. Only the harmonic
    /// operator (the harmonic-balance formulations) reads them.
    pub cyclic: Option<CyclicCoupling>,
    /// 3-D frictional contacts (a normal row and two tangent rows each, under the Coulomb
    /// disk); empty: none.
    pub frictional_contacts: Vec<FrictionalContact>,
}

/// A structure ready for every method: the model, its first finite natural frequency
/// `omega_1` (the unit of `omega_ratio` in scenes and sweeps) and the dof whose displacement
/// outputs describe (`tip_*` fields, plots): the rod's tip, or a scene's `[output] dof`. The
/// forcing frequency is not part of it: runs take it as an argument.
#[derive(Debug, Clone)]
pub struct Structure {
    /// The semi-discrete model `M, D, K, load, G, g`.
    pub model: StructuralModel,
    /// First finite natural frequency (rad per unit time).
    pub omega_1: f64,
    /// The observed dof (0-based).
    pub observed_dof: usize,
}

/// Why a [`StructuralModel`] cannot be used: the part, the value found and what is allowed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
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
    /// A reduced cyclic sector given to a formulation that reads `K`, `M`, `D` without the
    /// harmonic operator's interface couplings.
    #[error("a reduced cyclic sector cannot be solved by {formulation}: allowed the harmonic-balance formulations")]
    CyclicCoupling {
        /// The formulation.
        formulation: &'static str,
    },
    /// A dof of a sector list is out of range or in two sectors.
    #[error(
        "sector dof {dof} is out of range or in two sectors: allowed distinct dofs in 0..{dofs}"
    )]
    SectorDof {
        /// The dof.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
    /// A row between sectors names no row of the model or a dof out of range.
    #[error("row {row} between sectors with largest neighbour dof {dof}: allowed rows in 0..{rows} and dofs in 0..{dofs}")]
    NeighbourRow {
        /// The row index.
        row: usize,
        /// The model's rows.
        rows: usize,
        /// The largest dof of its neighbour part.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
    /// The load does not have one entry per dof.
    #[error("model load has length {found}: allowed {dofs} (one entry per dof)")]
    LoadLength {
        /// Length found.
        found: usize,
        /// `N`.
        dofs: usize,
    },
    /// The load is on a harmonic the formulation's basis does not hold.
    #[error("model load is on harmonic {harmonic}: allowed harmonics 0..={harmonics}")]
    LoadHarmonic {
        /// The highest harmonic of the load.
        harmonic: usize,
        /// The number of harmonics `H` of the basis.
        harmonics: usize,
    },
    /// A constant load (harmonic 0) was given a sine part.
    #[error(
        "constant load has sine part {value} on dof {dof}: allowed 0 (harmonic 0 has no sine)"
    )]
    ConstantLoadSine {
        /// The dof.
        dof: usize,
        /// The value found.
        value: f64,
    },
    /// A matrix entry, a load entry or a gap is NaN or infinite.
    #[error("model {part} holds a non-finite value {value}: allowed finite numbers")]
    NonFinite {
        /// `"stiffness matrix"`, `"mass matrix"`, `"damping matrix"`,
        /// `"load"` or `"contact gap"`.
        part: &'static str,
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
    /// A friction point's tangential row is on a dof that does not exist.
    #[error("friction point {point} is on dof {dof}: allowed 0..{dofs}")]
    FrictionDofOutOfRange {
        /// Index of the friction point.
        point: usize,
        /// The dof.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
    /// A friction coefficient is negative or not finite.
    #[error("friction point {point} has coefficient {value}: allowed a finite mu >= 0")]
    FrictionCoefficient {
        /// Index of the friction point.
        point: usize,
        /// The coefficient.
        value: f64,
    },
    /// A prescribed normal load is not a finite positive number.
    #[error("friction point {point} has normal load {value}: allowed a finite N > 0")]
    NormalLoad {
        /// Index of the friction point.
        point: usize,
        /// The load.
        value: f64,
    },
    /// A friction point refers to a contact that does not exist.
    #[error("friction point {point} is on contact {contact}: allowed 0..{contacts}")]
    FrictionContactOutOfRange {
        /// Index of the friction point.
        point: usize,
        /// The contact it names.
        contact: usize,
        /// Number of contacts.
        contacts: usize,
    },
    /// Two friction points on one contact (a two-dimensional tangent plane needs the
    /// disk-shaped Coulomb cone, not two independent intervals).
    #[error(
        "friction points {first} and {second} are both on contact {contact}: allowed one \
         friction point per contact (one tangential direction)"
    )]
    DuplicateFriction {
        /// The earlier point.
        first: usize,
        /// The later point.
        second: usize,
        /// The shared contact.
        contact: usize,
    },
    /// A frictional contact's row is on a dof that does not exist.
    #[error("frictional contact {point} is on dof {dof}: allowed 0..{dofs}")]
    FrictionalContactDofOutOfRange {
        /// Index of the frictional contact.
        point: usize,
        /// The dof.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
    /// A frictional contact's coefficient, gap or normal load is out of its range.
    #[error("frictional contact {point} has {part} {value}: allowed {allowed}")]
    FrictionalContactValue {
        /// Index of the frictional contact.
        point: usize,
        /// `"friction coefficient"`, `"gap"` or `"normal load"`.
        part: &'static str,
        /// The value found.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// A moving obstacle's gap is on a harmonic the formulation's basis does not hold.
    #[error(
        "frictional contact {point} has a moving gap on harmonic {harmonic}: allowed harmonics \
         1..={harmonics}"
    )]
    MovingGapHarmonic {
        /// Index of the frictional contact.
        point: usize,
        /// The highest harmonic of its gap.
        harmonic: usize,
        /// The number of harmonics `H` of the basis.
        harmonics: usize,
    },
    /// Two rows of a frictional contact are parallel.
    #[error(
        "frictional contact {point} has parallel rows: allowed a normal and two tangent rows \
         independent of each other"
    )]
    FrictionalContactParallelRows {
        /// Index of the frictional contact.
        point: usize,
    },
    /// A matrix entry given in code lies outside the `N x N` matrix.
    #[error("matrix entry ({row}, {col}) is outside the {dofs} x {dofs} matrix")]
    EntryOutOfRange {
        /// Its row (0-based).
        row: usize,
        /// Its column (0-based).
        col: usize,
        /// `N`.
        dofs: usize,
    },
    /// A matrix given in code could not be assembled (its storage could not be allocated).
    #[error(
        "a {dofs} x {dofs} matrix of {entries} entries could not be assembled (out of memory)"
    )]
    Assembly {
        /// `N`.
        dofs: usize,
        /// The entries given.
        entries: usize,
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

/// `Err` naming `omega` unless the forcing's angular frequency is finite and `> 0`.
pub(crate) fn check_omega(omega: f64) -> Result<(), InvalidOption> {
    let valid = omega.is_finite() && omega > 0.0;
    InvalidOption::check(valid, "omega", omega, "a finite angular frequency > 0")
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
        let couplings = self.cyclic.iter().flat_map(|c| &c.terms);
        for matrix in couplings.map(|t| &t.matrix) {
            let (rows, cols) = (matrix.nrows(), matrix.ncols());
            if rows != n || cols != n {
                let part = "cyclic coupling matrix";
                return Err(InvalidModel::MatrixSize {
                    part,
                    rows,
                    cols,
                    dofs: n,
                });
            }
            first_non_finite("cyclic coupling matrix", matrix.val())?;
        }
        let rows = self.rows().count();
        for neighbour in self.cyclic.iter().flat_map(|c| &c.neighbour_rows) {
            let dof = neighbour.part.largest_dof();
            if neighbour.row >= rows || dof >= n {
                return Err(InvalidModel::NeighbourRow {
                    row: neighbour.row,
                    rows,
                    dof,
                    dofs: n,
                });
            }
        }
        self.load.validate(n)?;
        contact::validate_rows(&self.contacts, &self.friction, n)?;
        frictional::validate_frictional(&self.frictional_contacts, n)?;
        Ok(())
    }

    /// [`InvalidModel::CyclicCoupling`] for a reduced cyclic sector: for the formulations
    /// (`formulation`) that read the matrices without the harmonic operator.
    pub(crate) fn refuse_cyclic(&self, formulation: &'static str) -> Result<(), InvalidModel> {
        match self.cyclic {
            Some(_) => Err(InvalidModel::CyclicCoupling { formulation }),
            None => Ok(()),
        }
    }

    /// Number of degrees of freedom `N`.
    pub fn dofs(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Number of contact constraints `m`.
    pub fn contact_count(&self) -> usize {
        self.contacts.len()
    }

    /// Number of friction points.
    pub fn friction_count(&self) -> usize {
        self.friction.len()
    }

    /// Every row of `G`: the contacts' normal rows, then the friction points' tangential
    /// rows, then the frictional contacts' rows (the order of the force unknowns of
    /// harmonic balance).
    pub fn rows(&self) -> impl Iterator<Item = &ContactRow> + '_ {
        self.contacts
            .iter()
            .map(|c| &c.row)
            .chain(self.friction.iter().map(|f| &f.tangent))
            .chain(self.frictional_contacts.iter().flat_map(|p| p.rows()))
    }

    /// Whether the model has friction: a friction point or a frictional contact.
    pub fn has_friction(&self) -> bool {
        !(self.friction.is_empty() && self.frictional_contacts.is_empty())
    }

    /// Number of rows of `G` ([`StructuralModel::rows`]).
    pub fn row_count(&self) -> usize {
        let frictional: usize = self.frictional_contacts.iter().map(|p| p.row_count()).sum();
        self.contacts.len() + self.friction.len() + frictional
    }

    /// Stiffness scale seen by the contacts: the mean of `g K g^T` over the rows of `G`
    /// (`K[dof, dof]` for a one-dof contact; 1 when there is no row). It converts a length
    /// into a force and is the default for the complementarity constant `c` and the unit
    /// of penalty stiffnesses.
    pub fn contact_stiffness_scale(&self) -> f64 {
        let rows = self.row_count();
        if rows == 0 {
            return 1.0;
        }
        let sum: f64 = self
            .rows()
            .map(|row| row.quadratic_form(&self.stiffness))
            .sum();
        sum / rows as f64
    }
}

impl StructuralModel {
    /// Static compliance matrix of the rows of `G` ([`StructuralModel::rows`]: contacts,
    /// then friction points), `C = G K^{-1} G^T` (row-major `m x m`): `C_ij` is how far
    /// row `i` moves under a unit force applied along row `j`. `None` without rows or when
    /// `K` cannot be factored.
    pub fn static_contact_compliance(&self) -> Option<Vec<f64>> {
        self.static_contact_response()
            .map(|(compliance, _)| compliance)
    }

    /// The static compliance matrix of the rows of `G` and how far each row moves under
    /// the load, `G K^{-1} f`.
    fn static_contact_response(&self) -> Option<(Vec<f64>, Vec<f64>)> {
        let rows: Vec<&ContactRow> = self.rows().collect();
        let m = rows.len();
        if m == 0 {
            return None;
        }
        let mut lu = semismooth::linalg::FaerSparseLu::new();
        lu.factor(&self.stiffness).ok()?;
        let mut rhs = self.load.forcing_cosine();
        lu.solve_in_place(&mut rhs).ok()?;
        let load_motion: Vec<f64> = rows.iter().map(|g| g.dot(&rhs)).collect();
        let mut compliance = vec![0.0; m * m];
        for (j, gj) in rows.iter().enumerate() {
            rhs.fill(0.0);
            gj.add_transpose_at(1.0, &mut rhs, 0);
            lu.solve_in_place(&mut rhs).ok()?;
            for (i, gi) in rows.iter().enumerate() {
                compliance[i * m + j] = gi.dot(&rhs);
            }
        }
        (compliance.iter().chain(&load_motion).all(|v| v.is_finite()))
            .then_some((compliance, load_motion))
    }

    /// Static stiffness seen by the contacts: the mean over the contacts of
    /// `1 / (G K^{-1} G^T)_ii`, the force that moves contact `i` by a unit length with the
    /// rest of the structure free. Independent of the mesh (for the rod: `EA / x_node`);
    /// `None` without contacts or when `K` cannot be factored.
    pub fn static_contact_stiffness(&self) -> Option<f64> {
        let m = self.row_count();
        mean_stiffness(diagonal(&self.static_contact_compliance()?, m))
    }

    /// Static stiffness per contact when the contacts that push the structure the same way
    /// close together: the static contact stiffness divided by the number of contacts that
    /// share the load, `rho(C+) / max_i C_ii`, with `C+` the compliance matrix
    /// `C = G K^{-1} G^T` keeping only the entries of contacts that close together under the
    /// load (same side, `C_ij > 0`, and static load factors `g_i / |G K^{-1} f|_i` within
    /// [`CLOSING_TOGETHER`] of each other; the other entries, among them those of the two
    /// sides of a clearance, set to 0) and `rho` its Perron root. The divisor is 1 for one
    /// contact, for contacts that do not feel each other or close one after the other, and
    /// `m` for `m` contacts that move and close as one; `None` when the static contact
    /// stiffness is.
    pub fn shared_contact_stiffness(&self) -> Option<f64> {
        let m = self.row_count();
        let (mut compliance, load_motion) = self.static_contact_response()?;
        let stiffness = mean_stiffness(diagonal(&compliance, m))?;
        let largest = diagonal(&compliance, m).fold(0.0, f64::max);
        // (A friction point's row has no gap: it is engaged at rest, as a closed contact.)
        let gaps = self.contacts.iter().map(|c| c.gap);
        let frictional = self.frictional_contacts.iter().flat_map(|p| p.offsets());
        let closing: Vec<f64> = gaps
            .chain(self.friction.iter().map(|_| 0.0))
            .chain(frictional)
            .zip(&load_motion)
            .map(|(gap, motion)| closing_load_factor(gap, *motion))
            .collect();
        for i in 0..m {
            for j in (0..m).filter(|&j| j != i) {
                let v = &mut compliance[i * m + j];
                if !(*v > 0.0 && close_together(closing[i], closing[j])) {
                    *v = 0.0;
                }
            }
        }
        // (Exactly 1 when the root is the largest compliance: one contact keeps its value.)
        let sharing = (perron_root(&compliance, m) / largest).max(1.0);
        Some(stiffness / sharing)
    }

    /// Default complementarity constant `c` of SSN-HB: ten times the static contact
    /// stiffness per contact when the contacts that push the structure the same way close
    /// together ([`StructuralModel::shared_contact_stiffness`]; the contact stiffness
    /// scale when `K` cannot be factored).
    ///
    /// With `m` contacts that move as one (a distributed contact), a contact's force is a
    /// share of the load, about `1 / m` of what one contact would carry, while the gap
    /// term `c (G u - g)` of its equation keeps one contact's scale: measured on a
    /// 1,000-element rod with 50 / 100 contacts over its last fifth, the shared stiffness
    /// brings the iterations from zero from 66 / not converged in 200 to 42 / 42. (`C` is
    /// dense: `8 m^2` bytes, counted in the run's memory estimate.)
    ///
    /// `c` converts a length into a force. Measured on the canonical rod (H = 20): with
    /// `c` between 1 and 30 times the static stiffness Newton converges from zero in 7-14
    /// iterations for 20 to 100,000 elements, and 10 gives the smallest truncation error;
    /// the local stiffness `K[tip, tip] = EA/h` grows with the mesh and from 200 elements on
    /// Newton no longer converges with it.
    pub fn default_complementarity_constant(&self) -> f64 {
        self.shared_contact_stiffness()
            .map(|k| DEFAULT_C_FACTOR * k)
            .unwrap_or_else(|| self.contact_stiffness_scale())
    }
}

/// Ratio of the default complementarity constant `c` to the static contact stiffness.
pub(crate) const DEFAULT_C_FACTOR: f64 = 10.0;

/// Entry `(i, i)` of a column-compressed matrix (0 when not stored).
pub fn diagonal_entry(matrix: &SparseMatrix, i: usize) -> f64 {
    semismooth::linalg::diagonal_entry(matrix.as_ref(), i).unwrap_or(0.0)
}

/// Entry `(i, j)` of a column-compressed matrix (0 when not stored).
fn diagonal_or_entry(matrix: &SparseMatrix, i: usize, j: usize) -> f64 {
    if i == j {
        return diagonal_entry(matrix, i);
    }
    let m = matrix.as_ref();
    m.row_idx_of_col(j)
        .zip(m.val_of_col(j))
        .filter(|(r, _)| *r == i)
        .map(|(_, v)| *v)
        .sum()
}

/// `Err(NonFinite)` with the first NaN or infinite entry of `values`.
fn first_non_finite(part: &'static str, values: &[f64]) -> Result<(), InvalidModel> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(InvalidModel::NonFinite { part, value }),
        None => Ok(()),
    }
}

/// The diagonal of the row-major `m x m` matrix `a`.
fn diagonal(a: &[f64], m: usize) -> impl Iterator<Item = f64> + '_ {
    a.iter().step_by(m + 1).copied()
}

/// Least ratio of the static load factors at which two contacts close for them to share the
/// load ([`StructuralModel::shared_contact_stiffness`]). Measured: the distributed contacts
/// over the last fifth of a rod whose gaps follow the first mode close within 0.84 of each
/// other (a tip load) and share it; a stop at 0.02 behind a pad at 0.01 on one mass closes
/// at twice the pad's load (0.5), and counting the two as sharing halves `c` to where the
/// solve from zero of that chain stagnates at H = 20 (`c` from 0.05 to 0.8 failed in 4 of 5
/// runs, from 1.1 to 1000 none).
pub const CLOSING_TOGETHER: f64 = 0.75;

/// The load factor at which a contact of gap `gap` closes when its point moves `motion`
/// along its normal per unit load (either way: the response oscillates): `gap / |motion|`;
/// 0 for a contact closed at rest, infinite for one the load does not move.
fn closing_load_factor(gap: f64, motion: f64) -> f64 {
    if gap <= 0.0 {
        0.0
    } else {
        gap / motion.abs()
    }
}

/// Whether two contacts closing at the load factors `a` and `b` close together: both closed
/// at rest, or `min(a, b) / max(a, b) >= CLOSING_TOGETHER` (none closes when the load does
/// not move it).
fn close_together(a: f64, b: f64) -> bool {
    if a == 0.0 || b == 0.0 {
        return a == b;
    }
    a.is_finite() && b.is_finite() && a.min(b) >= CLOSING_TOGETHER * a.max(b)
}

/// Perron root of the symmetric non-negative `m x m` matrix `a` (row-major): power
/// iteration from the vector of ones, stopped when the Collatz-Wielandt bounds
/// `min_i (a x)_i / x_i <= rho <= max_i (a x)_i / x_i` agree to `1e-6` relative, or when
/// the upper bound (non-increasing along the iteration) no longer falls by `1e-9` relative
/// (a reducible matrix, whose lower bound stays at a smaller block's root), at most 1,000
/// iterations; the upper bound is returned.
fn perron_root(a: &[f64], m: usize) -> f64 {
    let mut x = vec![1.0; m];
    let mut y = vec![0.0; m];
    let mut upper = f64::INFINITY;
    for _ in 0..1000 {
        for (i, yi) in y.iter_mut().enumerate() {
            *yi = a[i * m..(i + 1) * m]
                .iter()
                .zip(&x)
                .map(|(a, x)| a * x)
                .sum();
        }
        let (mut lower, mut high) = (f64::INFINITY, 0.0f64);
        // (Every `x_i > 0`: it starts at 1 and is floored below.)
        for (yi, xi) in y.iter().zip(&x) {
            let ratio = yi / xi;
            lower = lower.min(ratio);
            high = high.max(ratio);
        }
        let stalled = high >= upper * (1.0 - 1e-9);
        upper = high;
        let norm = y.iter().fold(0.0f64, |a, v| a.max(*v));
        if norm.is_nan() || norm <= 0.0 || high - lower <= 1e-6 * high || stalled {
            break;
        }
        for (xi, yi) in x.iter_mut().zip(&y) {
            // Floored so that a contact that no other one feels keeps a positive entry.
            *xi = (yi / norm).max(f64::MIN_POSITIVE);
        }
    }
    upper
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
            frictional_contacts: Vec::new(),
            mass: matrix(2.0, 0.5),
            damping: Some(matrix(0.2, -0.1)),
            stiffness: matrix(2.0, -1.0),
            load: HarmonicLoad::cosine(vec![0.0, 0.0, 1.0]),
            contacts: vec![ContactPoint::new(2, 0.1)],
            friction: Vec::new(),
            cyclic: None,
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
        m.load = HarmonicLoad::cosine(vec![0.0; 4]);
        assert_eq!(
            m.validate(),
            Err(InvalidModel::LoadLength { found: 4, dofs: 3 })
        );
        let mut m = chain();
        m.load = HarmonicLoad::cosine(vec![0.0, f64::INFINITY, 1.0]);
        assert_eq!(
            m.validate(),
            Err(InvalidModel::NonFinite {
                part: "load",
                value: f64::INFINITY
            })
        );
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
        // The frequency is the formulations' argument: each names it in its own error.
        let options = crate::hb::HbOptions::default();
        let message = crate::hb::SsnHb::new(&chain(), 0.0, &options)
            .unwrap_err()
            .to_string();
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

    /// K = tridiag(-1, 2, -1) on 3 dofs: `K^-1 = [[3, 2, 1], [2, 4, 2], [1, 2, 3]] / 4`.
    /// Contacts on dofs 0 and 2 pushing the same way: `C = [[3, 1], [1, 3]] / 4`, Perron
    /// root 1, so the load is shared by `1 / (3/4) = 4/3` contacts and the shared stiffness
    /// is `(4/3) (3/4) / 1 = 1` when they close together: equal gaps under the symmetric load
    /// `f = (1, 0, 1)` (`K^-1 f = (1, 1, 1)`), or gaps 1/30 and 0.1 under a load on dof 2
    /// (`K^-1 f = (1, 2, 3) / 4`, both close at the load factor 0.4/3). Equal gaps under the
    /// load on dof 2 close at load factors 0.4 and 0.4/3, one after the other: no sharing,
    /// the static stiffness 4/3. From opposite sides they push each other away (`C_02 < 0`)
    /// and share nothing: 4/3 again. One contact: the static stiffness.
    #[test]
    fn shared_stiffness_divides_by_the_contacts_that_close_together() {
        let mut model = chain();
        assert_eq!(
            model.shared_contact_stiffness(),
            model.static_contact_stiffness()
        );
        model.contacts = vec![ContactPoint::new(0, 0.1), ContactPoint::new(2, 0.1)];
        let compliance = model.static_contact_compliance().unwrap();
        for (got, want) in compliance.iter().zip([0.75, 0.25, 0.25, 0.75]) {
            assert!((got - want).abs() < 1e-15, "{compliance:?}");
        }
        let one_after_the_other = model.shared_contact_stiffness().unwrap();
        assert!((one_after_the_other - 4.0 / 3.0).abs() < 1e-12);
        model.contacts[0].gap = 0.1 / 3.0;
        let shared = model.shared_contact_stiffness().unwrap();
        assert!((shared - 1.0).abs() < 1e-12, "{shared}");
        model.contacts[0].gap = 0.1;
        model.load = HarmonicLoad::cosine(vec![1.0, 0.0, 1.0]);
        let shared = model.shared_contact_stiffness().unwrap();
        assert!((shared - 1.0).abs() < 1e-12, "{shared}");
        model.contacts[1] = ContactPoint::on_side(2, 0.1, ContactDirection::Negative);
        let static_stiffness = model.static_contact_stiffness().unwrap();
        assert!((static_stiffness - 4.0 / 3.0).abs() < 1e-14);
        assert_eq!(model.shared_contact_stiffness(), Some(static_stiffness));
    }

    /// The Perron root of random symmetric non-negative matrices (sizes around small
    /// block boundaries) against the largest eigenvalue from nalgebra's symmetric
    /// eigensolver, to the Collatz-Wielandt stopping rule's 1e-6 relative.
    #[test]
    fn perron_root_is_the_largest_eigenvalue_of_a_nonnegative_symmetric_matrix() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for m in [1, 2, 3, 7, 8, 9, 40] {
            let mut a = vec![0.0; m * m];
            for i in 0..m {
                for j in 0..=i {
                    // Sparse-ish coupling, positive diagonal (as a compliance has).
                    let v = if i == j {
                        1.0 + uniform()
                    } else {
                        (uniform() - 0.5).max(0.0)
                    };
                    a[i * m + j] = v;
                    a[j * m + i] = v;
                }
            }
            let eigen = nalgebra::DMatrix::from_row_slice(m, m, &a).symmetric_eigen();
            let largest = eigen.eigenvalues.iter().fold(f64::MIN, |a, v| a.max(*v));
            let rho = perron_root(&a, m);
            assert!(
                (rho - largest).abs() <= 1e-6 * largest,
                "m = {m}: {rho} vs {largest}"
            );
        }
        // Reducible: two blocks with roots 3 and 1 (the lower bound stays at 1).
        let blocks = [
            2.0, 1.0, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ];
        assert!((perron_root(&blocks, 4) - 3.0).abs() < 1e-6);
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
