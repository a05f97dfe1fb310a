//! Hill's method on a harmonic-balance solution, and the stability of a cyclic sector's
//! travelling wave one nodal-diameter family at a time.
//!
//! # Why a sector's own Jacobian is not enough
//!
//! The full disk's travelling wave is invariant under `Q`: shift every sector by one and
//! the time by `EO T / N` (sector `s + 1` does sector `s`'s motion delayed by `EO T / N`).
//! A perturbation `e^{lambda t} p(t)` of the full disk (`p` of period `T`) splits into the
//! eigenspaces of `Q`, whose eigenvalues are the `N`-th roots of unity `e^{i theta_r}`,
//! `theta_r = 2 pi r / N`: in family `r` harmonic `k` of sector `s + 1` is
//! `e^{-i (k phi - theta_r)}` times sector `s`'s (`phi = 2 pi EO / N`). Family 0 is the
//! forced response's own interface condition (the sector's Hill problem); the others are
//! the same sector with the interface phase `k phi - theta_r` in place of `k phi`, on the
//! coupling matrices and the neighbour parts of contact rows alike. The full disk's Hill
//! problem is block diagonal in these `N` families (exactly, on the AFT samples, when the
//! delay `EO T / N` is a whole number of samples), so its multipliers are the union of the
//! `N` sector problems'; family `N - r` holds the conjugates of family `r`'s. In the time
//! domain the families are delay equations (the neighbour is this sector delayed), which
//! is why the decomposition is done on the harmonics.
//!
//! # Hill's problem
//!
//! On the basis `e^{i k w t}`, `k = -H..H`, with `s_k = lambda + i k w`, unknowns
//! `(p_k, v_k = s_k p_k, Lambda_k)`:
//!
//! - `lambda p_k = v_k - i k w p_k`,
//! - `lambda M_k v_k = -K_k p_k - D_k v_k - i k w M_k v_k + (G^T Lambda)_k`,
//! - `0 = c sum_l H_{k-l} G_l p_l + Lambda_k - sum_l H_{k-l} Lambda_l` (SSN-HB: the
//!   generalized Jacobian of the complementarity rows; penalty HB instead adds
//!   `k_p G^T H G` to `K`),
//!
//! `H_d = (1/Nt) sum_n h_n e^{-i d theta_n}` the DFT of the switching samples `h_n` of the
//! solution (1 where the contact is closed). The finite generalized eigenvalues `lambda`
//! of this pencil are the Floquet exponents, each repeated at `lambda + i j w`; the copy
//! kept is the one whose eigenvector's displacement is centred on harmonic 0
//! (`|sum k |p_k|^2 / sum |p_k|^2| <= 1/2`, a rule per eigenvector, so the full disk keeps
//! exactly the lifts of the families' kept ones), and
//! the multiplier is `e^{lambda T}`. The verdict carries the harmonic-balance error of
//! the switching samples, as the time-domain monodromy carries that of the switching
//! instants.

use std::f64::consts::PI;

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{c64, Mat};
use semismooth::floquet::Multipliers;

use super::StabilityError;
use crate::model::{ContactRow, CouplingSource, SparseMatrix, StructuralModel};

/// A shifted eigenvalue `nu` below this fraction of the largest is an infinite `lambda` (a
/// massless or constrained direction; the Jordan blocks of a constraint of index 2 or 3
/// spread `nu = 0` to about the cube root of the rounding).
const INFINITE: f64 = 1e-4;

/// The shift `sigma = (SHIFT.0 + i SHIFT.1) w` of the inverted pencil: right of every
/// decaying exponent and off the imaginary axis.
const SHIFT: (f64, f64) = (0.37, 0.29);

/// An eigenvector is centred on harmonic 0 when its displacement's mean harmonic
/// `sum k |p_k|^2 / sum |p_k|^2` is within this of 0: one copy of each exponent's `2H + 1`.
const CENTRED: f64 = 0.5;

/// How a closed contact acts in the perturbation: held by its multiplier (SSN-HB, with its
/// complementarity constant), or a penalty spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ClosedLaw {
    /// SSN-HB with the complementarity constant `c`.
    Multiplier(f64),
    /// Penalty HB with the penalty stiffness `k_p`.
    Penalty(f64),
}

/// Hill's problem of one solution: the model, the basis, and the switching samples of
/// every normal contact.
pub(crate) struct HillProblem<'a> {
    pub(crate) model: &'a StructuralModel,
    pub(crate) harmonics: usize,
    pub(crate) omega: f64,
    /// `active[i][n]`: contact `i` is closed at sample `n` of `Nt`.
    pub(crate) active: Vec<Vec<bool>>,
    pub(crate) law: ClosedLaw,
}

/// The families `r` whose multipliers are computed (`0..=N/2`; the others are conjugates)
/// and the number of sectors `N` (1 for a model that is not a cyclic sector).
pub(crate) fn families(model: &StructuralModel) -> (Vec<usize>, usize) {
    let sectors = model.cyclic.as_ref().map_or(1, |c| c.sectors.max(1));
    ((0..=sectors / 2).collect(), sectors)
}

impl HillProblem<'_> {
    /// The finite generalized eigenvalues `lambda` of family `r`'s pencil (interface phase
    /// `k phi - 2 pi r / N` on harmonic `k`), each with its eigenvector's mean harmonic
    /// (`NaN` where the eigenvector is not finite: a repeated eigenvalue).
    pub(crate) fn family_exponents(&self, r: usize) -> Result<Vec<(f64, c64)>, StabilityError> {
        self.family_exponents_on(r, &self.source_matrices())
    }

    /// [`HillProblem::family_exponents`] with the model's dense `[K, M, D]` built once.
    fn family_exponents_on(
        &self,
        r: usize,
        sources: &[Mat<c64>; 3],
    ) -> Result<Vec<(f64, c64)>, StabilityError> {
        let (_, sectors) = families(self.model);
        let theta = 2.0 * PI * (r % sectors) as f64 / sectors as f64;
        let (a, b) = self.pencil(theta, sources);
        // Shift and invert: `C = (A - sigma B)^{-1} B` has the eigenvalues
        // `nu = 1 / (lambda - sigma)` with the same eigenvectors, the infinite `lambda` at
        // `nu = 0` (a standard Schur form, where the QZ iteration on this pencil's many
        // infinite eigenvalues was measured to return eigenpairs with residuals of order 1).
        let sigma = c64::new(SHIFT.0 * self.omega, SHIFT.1 * self.omega);
        let shifted = &a - &b * faer::Scale(sigma);
        let c = PartialPivLu::new(shifted.as_ref()).solve(&b);
        let eigen = c.eigen().map_err(|_| StabilityError::InvalidOption {
            name: "Hill pencil",
            value: f64::NAN,
            allowed: "a pencil whose shifted eigendecomposition converges",
        })?;
        let largest = (0..c.nrows()).fold(0.0f64, |m, i| m.max(eigen.S()[i].norm()));
        let (n, size) = (self.model.dofs(), 2 * self.harmonics + 1);
        let mut finite = Vec::new();
        for i in 0..c.nrows() {
            let nu = eigen.S()[i];
            if nu.norm().is_nan() || nu.norm() <= INFINITE * largest {
                continue;
            }
            let lambda = sigma + c64::new(1.0, 0.0) / nu;
            let vector = eigen.U().col(i);
            let (mut weight, mut moment) = (0.0, 0.0);
            for j in 0..size {
                let w: f64 = (0..n).map(|d| vector[j * n + d].norm_sqr()).sum();
                weight += w;
                moment += (j as f64 - self.harmonics as f64) * w;
            }
            finite.push((moment / weight, lambda));
        }
        Ok(finite)
    }

    /// The multipliers `e^{lambda T}` of family `r`: one per exponent, the copy centred on
    /// harmonic 0 (module documentation). `Err` when an eigenvector is not finite (a
    /// repeated eigenvalue whose copy cannot be told).
    pub(crate) fn family_multipliers(&self, r: usize) -> Result<Vec<(f64, f64)>, StabilityError> {
        self.family_multipliers_on(r, &self.source_matrices())
    }

    /// [`HillProblem::family_multipliers`] with the model's dense `[K, M, D]` built once.
    fn family_multipliers_on(
        &self,
        r: usize,
        sources: &[Mat<c64>; 3],
    ) -> Result<Vec<(f64, f64)>, StabilityError> {
        let exponents = self.family_exponents_on(r, sources)?;
        if let Some(&(centre, _)) = exponents.iter().find(|(c, _)| !c.is_finite()) {
            return Err(StabilityError::InvalidOption {
                name: "Hill eigenvector mean harmonic",
                value: centre,
                allowed: "finite (the eigenvalue is repeated)",
            });
        }
        let period = 2.0 * PI / self.omega;
        Ok(exponents
            .iter()
            .filter(|(centre, _)| centre.abs() <= CENTRED)
            .map(|&(_, lambda)| {
                let mu = c64::from_polar((lambda.re * period).exp(), lambda.im * period);
                (mu.re, mu.im)
            })
            .collect())
    }

    /// The multipliers of every family (module documentation).
    pub(crate) fn multipliers(&self) -> Result<Multipliers, StabilityError> {
        let (list, sectors) = families(self.model);
        let sources = self.source_matrices();
        let mut values = Vec::new();
        for r in list {
            let family = self.family_multipliers_on(r, &sources)?;
            if r != 0 && 2 * r != sectors {
                values.extend(family.iter().map(|&(re, im)| (re, -im)));
            }
            values.extend(family);
        }
        Ok(Multipliers::from_values(values))
    }

    /// `(A, B)` of the pencil `A x = lambda B x` of family phase `theta` (`sources` the
    /// model's dense `[K, M, D]`).
    fn pencil(&self, theta: f64, sources: &[Mat<c64>; 3]) -> (Mat<c64>, Mat<c64>) {
        let model = self.model;
        let (n, h) = (model.dofs(), self.harmonics as isize);
        let size = 2 * self.harmonics + 1;
        let m = match self.law {
            ClosedLaw::Multiplier(_) => self.active.len(),
            ClosedLaw::Penalty(_) => 0,
        };
        let dim = (2 * n + m) * size;
        let (mut a, mut b) = (Mat::<c64>::zeros(dim, dim), Mat::<c64>::zeros(dim, dim));
        let (v0, l0) = (n * size, 2 * n * size);
        let phase_step = model.cyclic.as_ref().map_or(0.0, |c| c.phase_step);
        let psi = |j: usize| (j as isize - h) as f64 * phase_step - theta;
        let mut matrices = sources.clone();
        for j in 0..size {
            let ikw = c64::new(0.0, (j as isize - h) as f64 * self.omega);
            let (p, v) = (j * n, v0 + j * n);
            self.phased_matrices(sources, psi(j), &mut matrices);
            let [k, mass, damping] = &matrices;
            for d in 0..n {
                a[(p + d, v + d)] = c64::new(1.0, 0.0);
                a[(p + d, p + d)] = -ikw;
                b[(p + d, p + d)] = c64::new(1.0, 0.0);
            }
            for r in 0..n {
                for c in 0..n {
                    a[(v + r, p + c)] = -k[(r, c)];
                    a[(v + r, v + c)] = -damping[(r, c)] - ikw * mass[(r, c)];
                    b[(v + r, v + c)] = mass[(r, c)];
                }
            }
        }
        let rows: Vec<&ContactRow> = model.contacts.iter().map(|c| &c.row).collect();
        for (i, row) in rows.iter().enumerate() {
            let dft = switching_dft(&self.active[i], self.harmonics);
            let part = self.neighbour_part(i);
            // Row i of harmonic j (`g + e^{-i psi} n`) and its column of G^T (`g + e^{+i psi} n`).
            let reads: Vec<_> = (0..size)
                .map(|j| row_vector(row, part, n, c64::from_polar(1.0, -psi(j))))
                .collect();
            let forces: Vec<_> = (0..size)
                .map(|j| row_vector(row, part, n, c64::from_polar(1.0, psi(j))))
                .collect();
            for (kj, f) in forces.iter().enumerate() {
                for (lj, g) in reads.iter().enumerate() {
                    let hd = dft[kj + size - 1 - lj];
                    match self.law {
                        ClosedLaw::Multiplier(c) => {
                            let row_index = l0 + kj * m + i;
                            for (d, &gd) in g.iter().enumerate() {
                                a[(row_index, lj * n + d)] += hd * gd * c;
                            }
                            a[(row_index, l0 + lj * m + i)] -= hd;
                        }
                        ClosedLaw::Penalty(kp) => {
                            for (r, &fr) in f.iter().enumerate() {
                                for (d, &gd) in g.iter().enumerate() {
                                    a[(v0 + kj * n + r, lj * n + d)] -= hd * fr * gd * kp;
                                }
                            }
                        }
                    }
                }
                if let ClosedLaw::Multiplier(_) = self.law {
                    a[(l0 + kj * m + i, l0 + kj * m + i)] += c64::new(1.0, 0.0);
                    for (d, &fd) in f.iter().enumerate() {
                        a[(v0 + kj * n + d, l0 + kj * m + i)] += fd;
                    }
                }
            }
        }
        (a, b)
    }

    /// The neighbour part of normal contact `i` (a row between sectors), if any.
    fn neighbour_part(&self, i: usize) -> Option<&ContactRow> {
        let coupling = self.model.cyclic.as_ref()?;
        (coupling.neighbour_rows.iter())
            .find(|r| r.row == i)
            .map(|r| &r.part)
    }

    /// The model's dense complex `[K, M, D]` without the cyclic couplings.
    fn source_matrices(&self) -> [Mat<c64>; 3] {
        let model = self.model;
        let n = model.dofs();
        let mut out = [(); 3].map(|_| Mat::<c64>::zeros(n, n));
        let one = c64::new(1.0, 0.0);
        add_sparse(&mut out[0], &model.stiffness, one);
        add_sparse(&mut out[1], &model.mass, one);
        if let Some(damping) = &model.damping {
            add_sparse(&mut out[2], damping, one);
        }
        out
    }

    /// `out` = dense complex `[K, M, D]` of harmonic phase `psi`: `sources`
    /// ([`HillProblem::source_matrices`]) plus each coupling with `e^{i sign psi}`.
    fn phased_matrices(&self, sources: &[Mat<c64>; 3], psi: f64, out: &mut [Mat<c64>; 3]) {
        for (target, source) in out.iter_mut().zip(sources) {
            target.copy_from(source);
        }
        if let Some(coupling) = &self.model.cyclic {
            for term in &coupling.terms {
                let index = match term.source {
                    CouplingSource::Stiffness => 0,
                    CouplingSource::Mass => 1,
                    CouplingSource::Damping => 2,
                };
                add_sparse(
                    &mut out[index],
                    &term.matrix,
                    c64::from_polar(1.0, term.sign * psi),
                );
            }
        }
    }
}

/// `target += factor matrix`.
fn add_sparse(target: &mut Mat<c64>, matrix: &SparseMatrix, factor: c64) {
    let matrix = matrix.as_ref();
    for col in 0..matrix.ncols() {
        for (r, &value) in matrix.row_idx_of_col(col).zip(matrix.val_of_col(col)) {
            target[(r, col)] += factor * value;
        }
    }
}

/// `H_d` for `d = -2H..=2H` (index `d + 2H`): the DFT of the switching samples.
fn switching_dft(active: &[bool], harmonics: usize) -> Vec<c64> {
    let nt = active.len().max(1) as f64;
    let span = 2 * harmonics as isize;
    (-span..=span)
        .map(|d| {
            (active.iter().enumerate())
                .filter(|(_, &a)| a)
                .map(|(n, _)| c64::from_polar(1.0, -2.0 * PI * d as f64 * n as f64 / nt))
                .sum::<c64>()
                / nt
        })
        .collect()
}

/// The dense row `g + phase n` on `n` dofs.
fn row_vector(row: &ContactRow, part: Option<&ContactRow>, n: usize, phase: c64) -> Vec<c64> {
    let mut out = vec![c64::new(0.0, 0.0); n];
    row.entries().for_each(|(d, a)| out[d] += a);
    if let Some(part) = part {
        part.entries().for_each(|(d, b)| out[d] += phase * b);
    }
    out
}
