//! Cyclic symmetry: a tuned disk of `N` identical sectors under an engine-order excitation
//! computed exactly on one sector.
//!
//! With `phi = 2 pi EO / N`, sector `s` does sector 0's motion delayed by `s EO T / N` (the
//! load on sector `s` lags sector 0's by `s phi`, [`HarmonicLoad::delayed_by_sector`]), so
//! harmonic `k` of sector `s` is `z_k e^{-i k s phi}` in the operator's complex convention
//! `z = a - i b` (`e^{+i k s phi}` on `a + i b`). The sector's right interface dofs are the
//! next sector's left ones: `z_k^R = e^{-i k phi} z_k^L`. Eliminating the right dofs with
//! `z = T_k z_r` (`T_k` the identity on the kept dofs, `e^{-i k phi}` from each left dof to
//! its right one) gives the reduced block
//!
//! `T_k^H A T_k = A_0 + e^{-i k phi} B + e^{+i k phi} C`
//!
//! for each source `A` of `K`, `M`, `D`: `A_0` the entries between kept dofs (right-right
//! entries moved onto their left dofs), `B` the kept-row/right-column entries moved onto the
//! left columns, `C` the right-row/kept-column entries moved onto the left rows
//! ([`CyclicSector::reduce`]; a [`CyclicCoupling`] of the harmonic operator, so the dense,
//! structured and condensed solves and continuation take it unchanged). The reduced load is
//! `T_k^H f_k`. Harmonic `k` lives on the nodal diameter `k EO mod N` folded to `0..=N/2`.
//!
//! References: Petrov (2004), a method for the forced response of bladed disks with
//! friction contacts by one sector; Laxalde, Thouverez, Lombard (2007), friction ring
//! dampers by cyclic symmetry and harmonic balance.

use std::f64::consts::PI;

use faer::sparse::Triplet;

use crate::model::{
    ContactPoint, ContactRow, CouplingSource, CouplingTerm, CyclicCoupling, FrictionPoint,
    HarmonicLoad, InvalidModel, NeighbourRow, SparseMatrix, StructuralModel, Structure,
};
use crate::rod::{natural_frequencies, ModelError};

/// Why a [`CyclicSector`] cannot be built: the part and the numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InvalidSector {
    /// The sector's own model is invalid.
    #[error("cyclic sector model: {0}")]
    Model(#[from] InvalidModel),
    /// No sector.
    #[error("cyclic sector count is 0: allowed N >= 1")]
    NoSectors,
    /// The left and right interface lists differ in length.
    #[error("cyclic interface has {left} left and {right} right dofs: allowed equal counts")]
    InterfaceLengths {
        /// Left dofs given.
        left: usize,
        /// Right dofs given.
        right: usize,
    },
    /// An interface dof is out of range or listed twice (on either side).
    #[error("cyclic interface dof {dof} is out of range or listed twice: allowed distinct dofs in 0..{dofs}")]
    InterfaceDof {
        /// The dof.
        dof: usize,
        /// The sector's dofs.
        dofs: usize,
    },
    /// A contact or friction row, or an observed dof, is on a right interface dof (write it
    /// on the matching left dof of the next sector).
    #[error("contact row {row} touches right interface dof {dof}: allowed rows on the interior and left dofs")]
    RowOnRightInterface {
        /// Index of the row (contacts first, then friction points).
        row: usize,
        /// The right dof.
        dof: usize,
    },
    /// The model is already a reduced sector.
    #[error("the sector model already carries cyclic couplings: allowed a plain sector model")]
    AlreadyReduced,
}

/// One sector of a tuned cyclic disk (module documentation): its model on all its dofs
/// (load on sector 0, contacts on its interior and left dofs), the matching left and right
/// interface dofs, the number of sectors `N` and the engine order `EO`.
#[derive(Debug, Clone)]
pub struct CyclicSector {
    model: StructuralModel,
    left: Vec<usize>,
    right: Vec<usize>,
    sectors: usize,
    engine_order: usize,
    /// The sector's dof of each reduced dof (the dofs not on the right interface, in order).
    kept: Vec<usize>,
    /// The reduced dof of each sector dof (a right dof: its left dof's).
    reduced_of: Vec<usize>,
    /// The rows that also take the next sector's dofs, on the sector's dofs.
    neighbour_rows: Vec<NeighbourRow>,
}

impl CyclicSector {
    /// The sector `model` with right interface dof `right[j]` the next sector's `left[j]`,
    /// `sectors = N` and `engine_order = EO` (any; it acts modulo `N`).
    pub fn new(
        model: StructuralModel,
        left: Vec<usize>,
        right: Vec<usize>,
        sectors: usize,
        engine_order: usize,
    ) -> Result<Self, InvalidSector> {
        model.validate()?;
        let n = model.dofs();
        if model.cyclic.is_some() {
            return Err(InvalidSector::AlreadyReduced);
        }
        if sectors == 0 {
            return Err(InvalidSector::NoSectors);
        }
        if left.len() != right.len() {
            return Err(InvalidSector::InterfaceLengths {
                left: left.len(),
                right: right.len(),
            });
        }
        let mut seen = vec![false; n];
        for &dof in left.iter().chain(&right) {
            if dof >= n || std::mem::replace(&mut seen[dof], true) {
                return Err(InvalidSector::InterfaceDof { dof, dofs: n });
            }
        }
        let mut is_right = vec![false; n];
        right.iter().for_each(|&d| is_right[d] = true);
        let rows = model.rows().enumerate();
        if let Some((row, dof)) = rows
            .flat_map(|(i, r)| r.dofs().iter().map(move |&d| (i, d)))
            .find(|&(_, d)| is_right[d])
        {
            return Err(InvalidSector::RowOnRightInterface { row, dof });
        }
        let kept: Vec<usize> = (0..n).filter(|&d| !is_right[d]).collect();
        let mut reduced_of = vec![0; n];
        kept.iter()
            .enumerate()
            .for_each(|(r, &d)| reduced_of[d] = r);
        for (&l, &r) in left.iter().zip(&right) {
            reduced_of[r] = reduced_of[l];
        }
        Ok(Self {
            model,
            left,
            right,
            sectors,
            engine_order,
            kept,
            reduced_of,
            neighbour_rows: Vec::new(),
        })
    }

    /// The sector with contacts between sectors: each [`NeighbourRow`] adds to row `row` of
    /// the sector model ([`StructuralModel::rows`]: contacts, friction points, frictional
    /// contacts) the part `part` on the next sector's dofs (numbered as this sector's, not
    /// on the right interface). The row then measures `g . u(t) + n . u(t - EO T / N)`, and
    /// its force acts on both sectors (module documentation of the coupling,
    /// [`NeighbourRow`]).
    pub fn with_neighbour_rows(mut self, rows: Vec<NeighbourRow>) -> Result<Self, InvalidSector> {
        let (count, n) = (self.model.rows().count(), self.model.dofs());
        for neighbour in &rows {
            let dof = neighbour.part.dofs().iter().copied().max().unwrap_or(0);
            if neighbour.row >= count || dof >= n {
                let (row, rows, dofs) = (neighbour.row, count, n);
                return Err(InvalidModel::NeighbourRow {
                    row,
                    rows,
                    dof,
                    dofs,
                }
                .into());
            }
            if let Some(&dof) = (neighbour.part.dofs().iter()).find(|d| self.right.contains(d)) {
                return Err(InvalidSector::RowOnRightInterface {
                    row: neighbour.row,
                    dof,
                });
            }
        }
        self.neighbour_rows = rows;
        Ok(self)
    }

    /// The rows between this sector and the next ([`CyclicSector::with_neighbour_rows`]).
    pub fn neighbour_rows(&self) -> &[NeighbourRow] {
        &self.neighbour_rows
    }

    /// The number of sectors `N`.
    pub fn sectors(&self) -> usize {
        self.sectors
    }

    /// The engine order `EO`.
    pub fn engine_order(&self) -> usize {
        self.engine_order
    }

    /// The left interface dofs.
    pub fn left(&self) -> &[usize] {
        &self.left
    }

    /// The right interface dofs (`right[j]` is the next sector's `left[j]`).
    pub fn right(&self) -> &[usize] {
        &self.right
    }

    /// The sector's model on all its dofs.
    pub fn model(&self) -> &StructuralModel {
        &self.model
    }

    /// The inter-sector phase of harmonic 1, `phi = 2 pi EO / N`.
    pub fn phase_step(&self) -> f64 {
        2.0 * PI * (self.engine_order % self.sectors) as f64 / self.sectors as f64
    }

    /// The nodal diameter of harmonic `k`: `k EO mod N`, folded to `0..=N/2`.
    pub fn nodal_diameter(&self, k: usize) -> usize {
        let d = (k * self.engine_order) % self.sectors;
        d.min(self.sectors - d)
    }

    /// The sector's dof of each reduced dof (its interior and left dofs, in order).
    pub fn reduced_dofs(&self) -> &[usize] {
        &self.kept
    }

    /// The reduced dof of sector dof `dof` (a right dof: its left dof's).
    pub fn reduced_dof(&self, dof: usize) -> Option<usize> {
        self.reduced_of.get(dof).copied()
    }

    /// The reduced model (module documentation): `K`, `M`, `D` and the load `T^H f` on the
    /// reduced dofs, the couplings `B`, `C` of each source with the phase `phi`, the
    /// contacts and friction rows renumbered.
    pub fn reduce(&self) -> StructuralModel {
        let m = &self.model;
        let phi = self.phase_step();
        let mut terms = Vec::new();
        let mut reduce_one = |a: &SparseMatrix, source: CouplingSource| {
            let (a0, b, c) = self.split(a);
            for (matrix, sign) in [(b, -1.0), (c, 1.0)] {
                if matrix.compute_nnz() > 0 {
                    terms.push(CouplingTerm {
                        source,
                        matrix,
                        sign,
                    });
                }
            }
            a0
        };
        let stiffness = reduce_one(&m.stiffness, CouplingSource::Stiffness);
        let mass = reduce_one(&m.mass, CouplingSource::Mass);
        let damping = (m.damping.as_ref()).map(|d| reduce_one(d, CouplingSource::Damping));
        let contacts = (m.contacts.iter())
            .map(|c| ContactPoint::on_row(self.reduce_row(&c.row), c.gap))
            .collect();
        let friction = (m.friction.iter())
            .map(|f| FrictionPoint {
                tangent: self.reduce_row(&f.tangent),
                ..f.clone()
            })
            .collect();
        StructuralModel {
            mass,
            damping,
            stiffness,
            load: self.reduce_load(phi),
            contacts,
            friction,
            cyclic: Some(
                CyclicCoupling::new(phi, self.sectors, terms).with_neighbour_rows(
                    (self.neighbour_rows.iter())
                        .map(|r| NeighbourRow {
                            row: r.row,
                            part: self.reduce_row(&r.part),
                        })
                        .collect(),
                ),
            ),
            frictional_contacts: (m.frictional_contacts.iter())
                .map(|c| c.map_rows(|r| self.reduce_row(r)))
                .collect(),
        }
    }

    /// The undamped, unloaded linear sector on nodal diameter `d` as a real model without
    /// contacts on `2 n` dofs (`n` reduced dofs): the Hermitian `Z = A_0 + e^{-i d 2pi/N} B +
    /// e^{+i d 2pi/N} C` of `K` and of `M` in the real form `[[Re Z, -Im Z], [Im Z, Re Z]]`
    /// on `(Re z, Im z)`, whose natural frequencies are those of the disk on nodal diameter
    /// `d`, each twice.
    pub fn nodal_diameter_model(&self, d: usize) -> StructuralModel {
        let angle = 2.0 * PI * (d % self.sectors) as f64 / self.sectors as f64;
        let real_form = |a: &SparseMatrix| {
            let n = self.kept.len();
            let (a0, b, c) = self.split(a);
            let mut t = Vec::new();
            let mut push = |m: &SparseMatrix, re: f64, im: f64| {
                let m = m.as_ref();
                for j in 0..n {
                    for (i, &v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                        t.push(Triplet::new(i, j, re * v));
                        t.push(Triplet::new(n + i, n + j, re * v));
                        t.push(Triplet::new(i, n + j, -im * v));
                        t.push(Triplet::new(n + i, j, im * v));
                    }
                }
            };
            push(&a0, 1.0, 0.0);
            push(&b, angle.cos(), -angle.sin());
            push(&c, angle.cos(), angle.sin());
            SparseMatrix::try_new_from_triplets(2 * n, 2 * n, &t).expect("entries within 2n")
        };
        let stiffness = real_form(&self.model.stiffness);
        let mass = real_form(&self.model.mass);
        StructuralModel::new(mass, stiffness, vec![0.0; 2 * self.kept.len()])
    }

    /// The lowest natural frequency of the disk: the least over the nodal diameters
    /// `0..=N/2` of [`CyclicSector::nodal_diameter_model`]'s lowest one.
    pub fn lowest_frequency(&self) -> Result<f64, ModelError> {
        let mut lowest = f64::INFINITY;
        for d in 0..=self.sectors / 2 {
            lowest = lowest.min(natural_frequencies(&self.nodal_diameter_model(d), 1)?[0]);
        }
        Ok(lowest)
    }

    /// The reduced sector as a structure for every harmonic-balance run: [`reduce`]d, its
    /// `omega_1` the disk's [`CyclicSector::lowest_frequency`], observed at the sector dof
    /// `observed_dof` (not a right interface dof).
    ///
    /// [`reduce`]: CyclicSector::reduce
    pub fn structure(&self, observed_dof: usize) -> Result<Structure, ModelError> {
        let observed = (self.reduced_of.get(observed_dof).copied())
            .filter(|_| !self.right.contains(&observed_dof))
            .ok_or(ModelError::InvalidParameter {
                name: "observed dof of a cyclic sector",
                value: observed_dof as f64,
                allowed: "a dof of the sector that is not on its right interface",
            })?;
        Ok(Structure {
            model: self.reduce(),
            omega_1: self.lowest_frequency()?,
            observed_dof: observed,
        })
    }

    /// `(A_0, B, C)` of one source (module documentation), on the reduced dofs.
    fn split(&self, a: &SparseMatrix) -> (SparseMatrix, SparseMatrix, SparseMatrix) {
        let n = self.kept.len();
        let mut is_right = vec![false; self.model.dofs()];
        self.right.iter().for_each(|&d| is_right[d] = true);
        let (mut a0, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
        let a = a.as_ref();
        for j in 0..a.ncols() {
            for (i, &v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                let entry = Triplet::new(self.reduced_of[i], self.reduced_of[j], v);
                match (is_right[i], is_right[j]) {
                    (false, true) => b.push(entry),
                    (true, false) => c.push(entry),
                    _ => a0.push(entry),
                }
            }
        }
        let build = |t: &[Triplet<usize, usize, f64>]| {
            SparseMatrix::try_new_from_triplets(n, n, t).expect("entries on the reduced dofs")
        };
        (build(&a0), build(&b), build(&c))
    }

    /// A row of the sector on the reduced dofs (it has no right dof: checked when built).
    fn reduce_row(&self, row: &ContactRow) -> ContactRow {
        let dofs = row.dofs().iter().map(|&d| self.reduced_of[d]).collect();
        ContactRow::new(dofs, row.coefficients().to_vec()).expect("a valid row renumbered")
    }

    /// `T_k^H f_k` per harmonic: a right dof's part `e^{+i k phi} f_R` (on `c - i s`) added
    /// to its left dof.
    fn reduce_load(&self, phi: f64) -> HarmonicLoad {
        let mut load = HarmonicLoad::zero(self.kept.len());
        for h in self.model.load.harmonics() {
            let (mut cosine, mut sine) = (vec![0.0; self.kept.len()], vec![0.0; self.kept.len()]);
            let (cos_a, sin_a) = (
                (h.harmonic as f64 * phi).cos(),
                (h.harmonic as f64 * phi).sin(),
            );
            for (dof, (&c, &s)) in h.cosine.iter().zip(&h.sine).enumerate() {
                let r = self.reduced_of[dof];
                if self.right.contains(&dof) {
                    // e^{i a} (c - i s) = (c cos a + s sin a) - i (s cos a - c sin a).
                    cosine[r] += c * cos_a + s * sin_a;
                    sine[r] += s * cos_a - c * sin_a;
                } else {
                    cosine[r] += c;
                    sine[r] += s;
                }
            }
            (load.add_harmonic(h.harmonic, &cosine, &sine)).expect("parts of the reduced length");
        }
        load
    }

    /// Sector `s`'s harmonic-major coefficients on all its dofs (length
    /// `dofs (2 H + 1)`) from the reduced ones `reduced` (length `reduced dofs (2 H + 1)`,
    /// e.g. the leading part of a harmonic-balance solution): sector 0's, delayed by
    /// `s EO T / N`.
    pub fn sector_coefficients(&self, reduced: &[f64], harmonics: usize, s: usize) -> Vec<f64> {
        let (nr, n) = (self.kept.len(), self.model.dofs());
        let mut full = vec![0.0; n * (2 * harmonics + 1)];
        for j in 0..(2 * harmonics + 1) {
            for (dof, &r) in self.reduced_of.iter().enumerate() {
                full[j * n + dof] = reduced[j * nr + r];
            }
        }
        // A right dof is the next sector's left dof: delayed by one sector.
        let mut right = full.clone();
        delay_coefficients(&mut right, n, harmonics, self.phase_step());
        for j in 0..(2 * harmonics + 1) {
            for &dof in &self.right {
                full[j * n + dof] = right[j * n + dof];
            }
        }
        delay_coefficients(&mut full, n, harmonics, s as f64 * self.phase_step());
        full
    }
}

/// Delays the harmonic-major coefficients `u` (`n` dofs, `H` harmonics) by the phase
/// `angle` of harmonic 1: harmonic `k`'s `(a, b)` becomes
/// `(a cos(k angle) - b sin(k angle), a sin(k angle) + b cos(k angle))`
/// (`a cos(k w t - k angle) + b sin(k w t - k angle)`).
pub fn delay_coefficients(u: &mut [f64], n: usize, harmonics: usize, angle: f64) {
    for k in 1..=harmonics {
        let (cos, sin) = ((k as f64 * angle).cos(), (k as f64 * angle).sin());
        let (a, b) = u[(2 * k - 1) * n..(2 * k + 1) * n].split_at_mut(n);
        for (a, b) in a.iter_mut().zip(b) {
            (*a, *b) = (*a * cos - *b * sin, *a * sin + *b * cos);
        }
    }
}
