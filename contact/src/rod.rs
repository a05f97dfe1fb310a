//! The clamped-free finite-element rod of Shi & Legrand (axial vibration only).
//!
//! `elements` two-node linear elements of length `h = L / elements`; node 0 is clamped, the
//! unknowns are the displacements of nodes `1..=elements` (dof `i - 1` for node `i`), the tip
//! is the last dof. Element matrices:
//! stiffness `EA/h [[1, -1], [-1, 1]]`, consistent mass `rhoA h / 6 [[2, 1], [1, 2]]`,
//! lumped mass `rhoA h / 2 diag(1, 1)`.
//!
//! The *modified* mass replaces the last element's consistent mass by `diag(rhoA h, 0)`: all of
//! that element's mass on its inner node, the contact (tip) node massless, total mass unchanged.
//! With a massive contact node the semi-discrete problem needs an impact law (a time-marching
//! answer depends on the restitution it imposes) while harmonic balance imposes none; with a
//! massless contact node the contact force is a bounded function and independent methods agree.

use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{DMatrix, SymmetricEigen};

use semismooth::linalg::FaerSparseLu;
use semismooth::{Factorize, LinearSolve};

use crate::dynamic::UnionPattern;
use crate::model::{
    sparse_mul_add, ContactPoint, HarmonicLoad, SparseMatrix, StructuralModel, Structure,
};

/// How the rod's mass is discretised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MassModel {
    /// Consistent (Galerkin) element mass matrices.
    #[default]
    Consistent,
    /// Lumped (diagonal) mass: half of each element's mass on each node.
    Lumped,
    /// Consistent, except the last element whose mass sits entirely on its inner node:
    /// the tip node is massless.
    Modified,
}

/// Damping model. Absent (`None` in [`RodSpec::damping`]) means no damping matrix at all.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DampingSpec {
    /// `D = (2 zeta / omega_1) K`: modal damping ratio `zeta` on the first mode.
    StiffnessProportional {
        /// Damping ratio of the first mode (dimensionless, >= 0).
        zeta: f64,
    },
    /// Rayleigh damping `D = alpha M + beta K`.
    Rayleigh {
        /// Mass-proportional coefficient (1/time, >= 0).
        alpha: f64,
        /// Stiffness-proportional coefficient (time, >= 0).
        beta: f64,
    },
}

/// Spatial shape of the load `p0 cos(omega t)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoadKind {
    /// Uniform distributed load of `p0` per unit length (consistent nodal vector).
    #[default]
    Distributed,
    /// A point force `p0` at the tip.
    Tip,
}

/// Forcing frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrequencySpec {
    /// `omega = ratio * omega_1` (first natural frequency of the discrete rod).
    Ratio(f64),
    /// `omega` in rad per unit time.
    Absolute(f64),
}

impl FrequencySpec {
    /// The angular frequency for a structure whose first natural frequency is `omega_1`.
    pub fn omega(self, omega_1: f64) -> f64 {
        match self {
            FrequencySpec::Ratio(r) => r * omega_1,
            FrequencySpec::Absolute(w) => w,
        }
    }

    /// The number the spec gives: the ratio or the absolute frequency.
    fn value(self) -> f64 {
        match self {
            FrequencySpec::Ratio(r) | FrequencySpec::Absolute(r) => r,
        }
    }
}

/// A unilateral contact at a node: `u_node - gap <= 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodContact {
    /// Node number, `1..=elements` (the tip is `elements`).
    pub node: usize,
    /// Initial gap (negative: preloaded against the obstacle at rest).
    pub gap: f64,
}

/// Everything that defines a rod problem (dimensionless units in the paper's case).
#[derive(Debug, Clone, PartialEq)]
pub struct RodSpec {
    /// Number of finite elements (>= 1).
    pub elements: usize,
    /// Rod length `L` (> 0).
    pub length: f64,
    /// Axial stiffness `E A` (> 0).
    pub axial_stiffness: f64,
    /// Mass per unit length `rho A` (> 0).
    pub mass_per_length: f64,
    /// Mass discretisation.
    pub mass: MassModel,
    /// Damping, `None` for an undamped rod.
    pub damping: Option<DampingSpec>,
    /// Load shape.
    pub load: LoadKind,
    /// Load amplitude `p0` (per unit length for a distributed load, a force at the tip).
    pub amplitude: f64,
    /// Forcing frequency.
    pub frequency: FrequencySpec,
    /// Unilateral contacts (empty: linear problem).
    pub contacts: Vec<RodContact>,
}

impl RodSpec {
    /// The paper's Fig. 1 case: 20 elements, `L = EA = rhoA = 1`, consistent mass,
    /// `zeta = 0.01` on mode 1, distributed load `p0 = 0.04` at `omega = omega_1`, tip gap 0.5.
    pub fn canonical() -> Self {
        RodSpec {
            elements: 20,
            length: 1.0,
            axial_stiffness: 1.0,
            mass_per_length: 1.0,
            mass: MassModel::Consistent,
            damping: Some(DampingSpec::StiffnessProportional { zeta: 0.01 }),
            load: LoadKind::Distributed,
            amplitude: 0.04,
            frequency: FrequencySpec::Ratio(1.0),
            contacts: vec![RodContact { node: 20, gap: 0.5 }],
        }
    }

    /// The rod with one contact at its tip with gap `gap`, or none (`None`: linear).
    pub fn with_tip_gap(self, gap: Option<f64>) -> Self {
        RodSpec {
            contacts: gap
                .map(|gap| {
                    vec![RodContact {
                        node: self.elements,
                        gap,
                    }]
                })
                .unwrap_or_default(),
            ..self
        }
    }
}

/// A rod problem ready for a formulation: the [`Structure`] (model, first natural frequency,
/// the tip as observed dof), through `Deref`, plus the spec it was built from.
#[derive(Debug, Clone)]
pub struct RodModel {
    /// The structure every method runs on.
    pub structure: Structure,
    /// The spec it was built from.
    pub spec: RodSpec,
}

impl RodModel {
    /// Dof index of the tip node.
    pub fn tip_dof(&self) -> usize {
        self.spec.elements - 1
    }

    /// The forcing frequency of the spec, resolved against the rod's `omega_1` (finite and
    /// `> 0`: [`build_rod`] checks it).
    pub fn omega(&self) -> f64 {
        self.spec.frequency.omega(self.structure.omega_1)
    }
}

impl std::ops::Deref for RodModel {
    type Target = Structure;
    fn deref(&self) -> &Structure {
        &self.structure
    }
}

impl std::ops::DerefMut for RodModel {
    fn deref_mut(&mut self) -> &mut Structure {
        &mut self.structure
    }
}

/// Why a model could not be built or analysed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A scalar parameter is outside its allowed range.
    #[error("invalid {name} = {value}: allowed {allowed}")]
    InvalidParameter {
        /// Which parameter.
        name: &'static str,
        /// The value received.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// A contact refers to a node that does not exist or is clamped.
    #[error("contact node {node} is out of range: allowed 1..={elements} (node 0 is clamped)")]
    ContactNodeOutOfRange {
        /// The node received.
        node: usize,
        /// Number of elements (= last node).
        elements: usize,
    },
    /// Two contacts on the same node.
    #[error("two contacts on node {node}: at most one contact per node")]
    DuplicateContactNode {
        /// The repeated node.
        node: usize,
    },
    /// More natural frequencies requested than the model has finite ones.
    #[error("{requested} natural frequencies requested, the model has {available} finite ones")]
    TooManyModes {
        /// Number requested.
        requested: usize,
        /// Number of finite natural frequencies (massive dofs).
        available: usize,
    },
    /// The stiffness matrix could not be factored (not positive definite or singular).
    #[error("stiffness matrix could not be factored: {reason}")]
    Factorization {
        /// Backend's description.
        reason: String,
    },
    /// Subspace iteration did not converge.
    #[error("natural frequencies did not converge in {iterations} iterations (relative change {change:e})")]
    EigenNotConverged {
        /// Iterations performed.
        iterations: usize,
        /// Last relative change of the requested frequencies.
        change: f64,
    },
}

/// `Err(InvalidParameter { name, value, allowed })` unless `value` is finite and `ok`.
fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    allowed: &'static str,
) -> Result<(), ModelError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            name,
            value,
            allowed,
        })
    }
}

fn check_positive(name: &'static str, value: f64) -> Result<(), ModelError> {
    check(name, value, value > 0.0, "a finite number > 0")
}

fn check_non_negative(name: &'static str, value: f64) -> Result<(), ModelError> {
    check(name, value, value >= 0.0, "a finite number >= 0")
}

fn check_finite(name: &'static str, value: f64) -> Result<(), ModelError> {
    check(name, value, true, "a finite number")
}

/// Largest element count accepted (a guard against absurd sizes, about 1.6 GB of matrices).
pub const MAX_ELEMENTS: usize = 10_000_000;

fn validate(spec: &RodSpec) -> Result<(), ModelError> {
    if spec.elements == 0 || spec.elements > MAX_ELEMENTS {
        return Err(ModelError::InvalidParameter {
            name: "elements",
            value: spec.elements as f64,
            allowed: "an integer in 1..=10000000",
        });
    }
    check_positive("length", spec.length)?;
    check_positive("axial_stiffness", spec.axial_stiffness)?;
    check_positive("mass_per_length", spec.mass_per_length)?;
    check_finite("amplitude", spec.amplitude)?;
    match spec.damping {
        Some(DampingSpec::StiffnessProportional { zeta }) => check_non_negative("zeta", zeta)?,
        Some(DampingSpec::Rayleigh { alpha, beta }) => {
            check_non_negative("alpha", alpha)?;
            check_non_negative("beta", beta)?;
        }
        None => {}
    }
    match spec.frequency {
        FrequencySpec::Ratio(r) => check_positive("omega_ratio", r)?,
        FrequencySpec::Absolute(w) => check_positive("omega", w)?,
    }
    let mut nodes: Vec<usize> = Vec::with_capacity(spec.contacts.len());
    for c in &spec.contacts {
        if c.node == 0 || c.node > spec.elements {
            return Err(ModelError::ContactNodeOutOfRange {
                node: c.node,
                elements: spec.elements,
            });
        }
        check_finite("gap", c.gap)?;
        if nodes.contains(&c.node) {
            return Err(ModelError::DuplicateContactNode { node: c.node });
        }
        nodes.push(c.node);
    }
    Ok(())
}

/// Assembles a symmetric tridiagonal-pattern matrix from per-element 2x2 blocks
/// `[[a, b], [b, d]]` on nodes `(e, e + 1)`, dropping the clamped node 0.
fn assemble_elements(
    elements: usize,
    block: impl Fn(usize) -> [f64; 3],
) -> Result<SparseMatrix, ModelError> {
    let mut triplets = Vec::with_capacity(4 * elements);
    for e in 0..elements {
        let [a, b, d] = block(e);
        // Element e joins nodes e and e + 1, i.e. dofs e - 1 and e.
        let right = e;
        if e > 0 {
            let left = e - 1;
            triplets.push(Triplet::new(left, left, a));
            triplets.push(Triplet::new(left, right, b));
            triplets.push(Triplet::new(right, left, b));
        }
        triplets.push(Triplet::new(right, right, d));
    }
    SparseColMat::try_new_from_triplets(elements, elements, &triplets).map_err(|e| {
        ModelError::Factorization {
            reason: format!("assembly failed: {e:?}"),
        }
    })
}

/// Builds the structural model of a rod and its first natural frequency; the spec's forcing
/// frequency, resolved against it, is [`RodModel::omega`].
///
/// ```
/// use semismooth_contact::rod::{build_rod, RodSpec};
/// let rod = build_rod(&RodSpec::canonical()).unwrap();
/// assert!((rod.omega_1 - 1.571200).abs() < 1e-6);
/// assert_eq!(rod.omega(), rod.omega_1); // the canonical rod is forced at omega_1
/// assert_eq!(rod.model.contacts[0].dof(), 19);
/// ```
pub fn build_rod(spec: &RodSpec) -> Result<RodModel, ModelError> {
    validate(spec)?;
    let n = spec.elements;
    let h = spec.length / n as f64;
    let k_e = spec.axial_stiffness / h;
    let m_e = spec.mass_per_length * h;
    let stiffness = assemble_elements(n, |_| [k_e, -k_e, k_e])?;
    let mass = assemble_elements(n, |e| match spec.mass {
        MassModel::Consistent => [m_e / 3.0, m_e / 6.0, m_e / 3.0],
        MassModel::Lumped => [m_e / 2.0, 0.0, m_e / 2.0],
        MassModel::Modified if e + 1 == n => [m_e, 0.0, 0.0],
        MassModel::Modified => [m_e / 3.0, m_e / 6.0, m_e / 3.0],
    })?;
    let mut load = vec![0.0; n];
    match spec.load {
        LoadKind::Distributed => {
            for e in 0..n {
                let half = 0.5 * spec.amplitude * h;
                if e > 0 {
                    load[e - 1] += half;
                }
                load[e] += half;
            }
        }
        LoadKind::Tip => load[n - 1] = spec.amplitude,
    }
    let contacts = spec
        .contacts
        .iter()
        .map(|c| ContactPoint::new(c.node - 1, c.gap))
        .collect();
    let mut model = StructuralModel {
        frictional_contacts: Vec::new(),
        mass,
        damping: None,
        stiffness,
        load: HarmonicLoad::cosine(load),
        contacts,
        friction: Vec::new(),
        cyclic: None,
    };
    let omega_1 = natural_frequencies(&model, 1)?[0];
    model.damping = match spec.damping {
        None => None,
        Some(DampingSpec::StiffnessProportional { zeta }) => Some(
            UnionPattern::linear_combination(n, &[&model.stiffness], &[2.0 * zeta / omega_1]),
        ),
        Some(DampingSpec::Rayleigh { alpha, beta }) => Some(UnionPattern::linear_combination(
            n,
            &[&model.stiffness, &model.mass],
            &[beta, alpha],
        )),
    };
    if !spec.frequency.omega(omega_1).is_finite() {
        return Err(ModelError::InvalidParameter {
            name: "omega_ratio",
            value: spec.frequency.value(),
            allowed: "a ratio whose frequency omega_ratio * omega_1 is finite",
        });
    }
    Ok(RodModel {
        structure: Structure {
            model,
            omega_1,
            observed_dof: n - 1,
        },
        spec: spec.clone(),
    })
}

fn to_dense(m: &SparseMatrix) -> DMatrix<f64> {
    let r = m.as_ref();
    let mut d = DMatrix::zeros(r.nrows(), r.ncols());
    for j in 0..r.ncols() {
        for (i, v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            d[(i, j)] += v;
        }
    }
    d
}

/// Rayleigh–Ritz on a basis `Y` (n x p): the generalized problem `K v = omega^2 M v`
/// restricted to span(Y), returned as the eigenvalues `nu = 1/omega^2` of
/// `L^{-1} (Y^T M Y) L^{-T}` with `Y^T K Y = L L^T`, descending, with Ritz vectors.
pub(crate) fn rayleigh_ritz(
    k_y: &DMatrix<f64>,
    m_y: &DMatrix<f64>,
    y: &DMatrix<f64>,
) -> Result<(Vec<f64>, DMatrix<f64>), ModelError> {
    let kr = y.transpose() * k_y;
    let mr = y.transpose() * m_y;
    let kr = 0.5 * (&kr + kr.transpose());
    let chol = kr.cholesky().ok_or_else(|| ModelError::Factorization {
        reason: "reduced stiffness is not positive definite".into(),
    })?;
    let l = chol.l();
    let singular = || ModelError::Factorization {
        reason: "reduced stiffness factor is singular".into(),
    };
    // L^{-1} M_r L^{-T} = (L^{-1} (L^{-1} M_r)^T)^T by two triangular solves (M_r symmetric).
    let b = l.solve_lower_triangular(&mr).ok_or_else(singular)?;
    let a = l
        .solve_lower_triangular(&b.transpose())
        .ok_or_else(singular)?
        .transpose();
    let a = 0.5 * (&a + a.transpose());
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let nu: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i]).collect();
    // Ritz vectors in the original coordinates: Y L^{-T} w (L^T x = w solved).
    let w = DMatrix::from_fn(eig.eigenvectors.nrows(), order.len(), |r, c| {
        eig.eigenvectors[(r, order[c])]
    });
    let vectors = y * l.tr_solve_lower_triangular(&w).ok_or_else(singular)?;
    Ok((nu, vectors))
}

/// Multiplies a sparse matrix by a dense block (column by column).
fn sparse_times(m: &SparseMatrix, x: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(m.nrows(), x.ncols());
    let columns = x.as_slice().chunks(x.nrows().max(1));
    for (o, xc) in out.as_mut_slice().chunks_mut(m.nrows().max(1)).zip(columns) {
        sparse_mul_add(m.as_ref(), 1.0, xc, o);
    }
    out
}

/// Relative change per subspace iteration below which the last estimate is accepted when
/// [`natural_frequencies`] reaches its iteration limit.
const ACCEPTED_EIGEN_CHANGE: f64 = 1e-9;

/// The `count` lowest natural frequencies `omega` of `K v = omega^2 M v` (rad per unit
/// time), ascending. Massless dofs have infinite frequencies and are not counted.
///
/// Small models (n <= 64) are solved densely; larger ones by subspace iteration
/// `Y <- K^{-1} M Y` with Rayleigh–Ritz (sparse LU of K, cost linear in n for a rod),
/// until the requested frequencies change by less than 1e-13 relative, or by less than
/// 1e-9 and no less than at the iteration before (the round-off level of large models), or,
/// after 200 iterations, by less than 1e-9 (clustered spectra converge slowly). A reduced
/// cyclic sector is refused: its frequencies are per nodal diameter
/// ([`crate::cyclic::CyclicSector::nodal_diameter_model`]).
pub fn natural_frequencies(model: &StructuralModel, count: usize) -> Result<Vec<f64>, ModelError> {
    let n = model.dofs();
    if let Some(coupling) = &model.cyclic {
        return Err(ModelError::InvalidParameter {
            name: "cyclic coupling phase of a model for natural frequencies",
            value: coupling.phase_step,
            allowed: "a model without cyclic couplings (a sector's nodal-diameter model)",
        });
    }
    if count == 0 {
        return Ok(Vec::new());
    }
    if count > n {
        return Err(ModelError::TooManyModes {
            requested: count,
            available: n,
        });
    }
    // The lowest `count` finite frequencies from the eigenvalues `nu = 1 / omega^2`
    // (descending); massless dofs give `nu = 0`.
    let lowest = |nu: &[f64]| -> Result<Vec<f64>, ModelError> {
        let nu_max = nu.iter().cloned().fold(0.0, f64::max);
        let freqs: Vec<f64> = nu
            .iter()
            .filter(|&&v| v > 1e-13 * nu_max)
            .map(|&v| 1.0 / v.sqrt())
            .collect();
        if freqs.len() < count {
            return Err(ModelError::TooManyModes {
                requested: count,
                available: freqs.len(),
            });
        }
        Ok(freqs[..count].to_vec())
    };
    if n <= 64 {
        let k = to_dense(&model.stiffness);
        let m = to_dense(&model.mass);
        let y = DMatrix::identity(n, n);
        let (nu, _) = rayleigh_ritz(&k, &m, &y)?;
        return lowest(&nu);
    }
    let factorization_failed =
        |e: semismooth::linalg::LinearSolveError| ModelError::Factorization {
            reason: e.to_string(),
        };
    let mut lu = FaerSparseLu::new();
    lu.factor(&model.stiffness).map_err(factorization_failed)?;
    let p = (2 * count + 8).min(n);
    // Smooth, linearly independent start vectors (low modes of a uniform chain).
    let mut y = DMatrix::from_fn(n, p, |i, j| {
        ((2 * j + 1) as f64 * std::f64::consts::FRAC_PI_2 * (i + 1) as f64 / n as f64).sin()
    });
    let mut previous: Option<Vec<f64>> = None;
    let max_iterations = 200;
    let mut change = f64::INFINITY;
    for iteration in 0..max_iterations {
        let previous_change = change;
        // Y <- K^{-1} M Y
        let mut z = sparse_times(&model.mass, &y);
        for column in z.as_mut_slice().chunks_exact_mut(n) {
            lu.solve_in_place(column).map_err(factorization_failed)?;
        }
        let kz = sparse_times(&model.stiffness, &z);
        let mz = sparse_times(&model.mass, &z);
        let (nu, vectors) = rayleigh_ritz(&kz, &mz, &z)?;
        let current = lowest(&nu)?;
        if let Some(prev) = &previous {
            change = current
                .iter()
                .zip(prev)
                .map(|(a, b)| ((a - b) / a).abs())
                .fold(0.0, f64::max);
            // Below `ACCEPTED_EIGEN_CHANGE` a change that no longer falls is round-off
            // (large models stall there: 1e5 rod elements near 1e-12), not convergence.
            if change < 1e-13 || (change < ACCEPTED_EIGEN_CHANGE && change >= previous_change) {
                return Ok(current);
            }
        }
        if change < ACCEPTED_EIGEN_CHANGE && previous.is_some() && iteration + 1 == max_iterations {
            // A cluster of nearly equal frequencies (e.g. a bladed disk's blade modes)
            // converges slowly: the last estimate, changing by less than 1e-9 relative per
            // iteration, is returned rather than nothing.
            return Ok(current);
        }
        previous = Some(current);
        // Normalise the Ritz vectors to keep the iteration well scaled.
        y = vectors;
        for mut col in y.column_iter_mut() {
            let norm = col.norm();
            if norm > 0.0 {
                col /= norm;
            }
        }
    }
    Err(ModelError::EigenNotConverged {
        iterations: max_iterations,
        change,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn spec(elements: usize, mass: MassModel) -> RodSpec {
        RodSpec {
            elements,
            mass,
            contacts: vec![RodContact {
                node: elements,
                gap: 0.5,
            }],
            ..RodSpec::canonical()
        }
    }

    #[test]
    fn canonical_first_frequency_matches_the_reference_value() {
        let rod = build_rod(&RodSpec::canonical()).unwrap();
        // The reference value is omega_1 = 1.571200 for 20 consistent elements (continuous: pi/2).
        assert!((rod.omega_1 - 1.571200).abs() < 5e-7, "{}", rod.omega_1);
    }

    #[test]
    fn consistent_mass_frequencies_match_the_closed_form_of_the_discrete_rod() {
        // Fixed-free chain with consistent mass: omega_j^2 = (6/h^2) (1 - cos t)/(2 + cos t),
        // t = (2j - 1) pi h / (2L) (exact eigenvalues of the tridiagonal pencil).
        for elements in [5usize, 20, 100, 1000] {
            let rod = build_rod(&spec(elements, MassModel::Consistent)).unwrap();
            let freqs = natural_frequencies(&rod.model, 3).unwrap();
            let h = 1.0 / elements as f64;
            for (j, f) in freqs.iter().enumerate() {
                let t = (2 * j + 1) as f64 * PI * h / 2.0;
                let exact = (6.0 / (h * h) * (1.0 - t.cos()) / (2.0 + t.cos())).sqrt();
                assert!(
                    ((f - exact) / exact).abs() < 1e-10,
                    "N={elements} mode {j}: {f} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn lumped_mass_frequencies_match_the_closed_form_of_the_discrete_rod() {
        // Lumped fixed-free chain (half a mass on the tip node):
        // omega_j = (2/h) sin(t/2), t = (2j - 1) pi h / (2L); 40 dofs go through the dense
        // solver, 4000 through subspace iteration.
        for elements in [40usize, 4000] {
            let rod = build_rod(&spec(elements, MassModel::Lumped)).unwrap();
            let freqs = natural_frequencies(&rod.model, 3).unwrap();
            let h = 1.0 / elements as f64;
            for (j, f) in freqs.iter().enumerate() {
                let t = (2 * j + 1) as f64 * PI * h / 2.0;
                let exact = 2.0 / h * (t / 2.0).sin();
                assert!(((f - exact) / exact).abs() < 1e-10, "N={elements} mode {j}");
            }
        }
    }

    #[test]
    fn modified_mass_keeps_total_mass_and_makes_the_tip_massless() {
        let rod = build_rod(&spec(20, MassModel::Modified)).unwrap();
        let m = to_dense(&rod.model.mass);
        let total: f64 = m.iter().sum::<f64>() + 0.0;
        // Sum of all entries = total mass carried by free nodes (the clamped node's share of
        // the first element is missing): rhoA (L - h/2) for the consistent matrix with node 0
        // removed; the modified matrix has the same total.
        let consistent = to_dense(
            &build_rod(&spec(20, MassModel::Consistent))
                .unwrap()
                .model
                .mass,
        );
        assert!((total - consistent.iter().sum::<f64>()).abs() < 1e-14);
        assert!(m.row(19).iter().all(|v| *v == 0.0));
        let freqs = natural_frequencies(&rod.model, 19).unwrap();
        assert_eq!(freqs.len(), 19);
        assert!(matches!(
            natural_frequencies(&rod.model, 20),
            Err(ModelError::TooManyModes {
                requested: 20,
                available: 19
            })
        ));
    }

    #[test]
    fn subspace_iteration_agrees_with_the_dense_eigensolver_for_modified_mass() {
        // 64 dofs goes dense, 65 dofs through subspace iteration: compare 65 with the
        // continuous limit and with a dense solve of the same matrices.
        let rod = build_rod(&spec(65, MassModel::Modified)).unwrap();
        let iterative = natural_frequencies(&rod.model, 4).unwrap();
        let k = to_dense(&rod.model.stiffness);
        let m = to_dense(&rod.model.mass);
        let (nu, _) = rayleigh_ritz(&k, &m, &DMatrix::identity(65, 65)).unwrap();
        for j in 0..4 {
            let dense = 1.0 / nu[j].sqrt();
            assert!(((iterative[j] - dense) / dense).abs() < 1e-11);
        }
    }

    #[test]
    fn distributed_load_is_consistent_and_sums_to_the_resultant() {
        let rod = build_rod(&RodSpec::canonical()).unwrap();
        let f = &rod.model.load.forcing_cosine();
        // Resultant of p0 over (0, L] minus the clamped node's half element.
        let total: f64 = f.iter().sum();
        assert!((total - 0.04 * (1.0 - 0.5 / 20.0)).abs() < 1e-15);
        assert!((f[19] - 0.04 / 40.0).abs() < 1e-15);
        assert!((rod.omega() - rod.omega_1).abs() < 1e-15);
    }

    #[test]
    fn stiffness_proportional_damping_gives_the_requested_modal_ratio() {
        let rod = build_rod(&RodSpec::canonical()).unwrap();
        let d = to_dense(rod.model.damping.as_ref().unwrap());
        let k = to_dense(&rod.model.stiffness);
        // D = beta K with beta = 2 zeta / omega_1: modal ratio on mode 1 is beta omega_1 / 2.
        let beta = d[(0, 0)] / k[(0, 0)];
        assert!((beta * rod.omega_1 / 2.0 - 0.01).abs() < 1e-15);
    }

    #[test]
    fn invalid_specs_are_rejected_with_the_field_name() {
        let bad = [
            (
                RodSpec {
                    elements: 0,
                    ..RodSpec::canonical()
                },
                "elements",
            ),
            (
                RodSpec {
                    length: f64::NAN,
                    ..RodSpec::canonical()
                },
                "length",
            ),
            (
                RodSpec {
                    frequency: FrequencySpec::Ratio(-1.0),
                    ..RodSpec::canonical()
                },
                "omega_ratio",
            ),
            (
                RodSpec {
                    damping: Some(DampingSpec::StiffnessProportional { zeta: -0.1 }),
                    ..RodSpec::canonical()
                },
                "zeta",
            ),
        ];
        for (s, field) in bad {
            let err = build_rod(&s).unwrap_err();
            assert!(err.to_string().contains(field), "{err}");
        }
        let out = RodSpec {
            contacts: vec![RodContact { node: 21, gap: 0.5 }],
            ..RodSpec::canonical()
        };
        assert_eq!(
            build_rod(&out).unwrap_err(),
            ModelError::ContactNodeOutOfRange {
                node: 21,
                elements: 20
            }
        );
    }
}
