//! Structures built in code for the shipped `[model]` scenes, their generating examples and
//! tests: a (mistuned) bladed disk with any number of blades, and an Euler–Bernoulli
//! cantilever with a contact pad at its tip.
//!
//! **Bladed disk.** `B` sectors in a ring; sector `j` has a disk dof `d_j` (0-based `3j`)
//! and a blade tip dof `b_j` (`3j + 1`), both of unit mass, and a massless contact pad
//! `p_j` (`3j + 2`). Springs: `k_g = 1` from each disk dof to the ground, `k_d = 1` between
//! neighbouring disk dofs (cyclic), the blade `k_b (1 + delta_j)` between `d_j` and `b_j`
//! with `k_b = 1` and the deterministic mistuning `delta_j = mistuning sin(2.3 j)`, and the
//! pad `k_c = 10` between `b_j` and `p_j` (a free massless pad carries no force: the pads
//! change no natural frequency). The load shape is a unit force on every blade tip, in
//! phase (engine order 0).
//!
//! **Cantilever.** Beam units `L = EI = rhoA = 1`; `n` Hermite-cubic elements of length
//! `h = 1/n`, node 0 clamped; node `i = 1..=n` has the deflection `w_i` (0-based dof
//! `2i - 2`) and the rotation `theta_i` (`2i - 1`). Element matrices (dofs `w_a, theta_a,
//! w_b, theta_b`):
//!
//! ```text
//! K_e = EI/h^3 [[12, 6h, -12, 6h], [6h, 4h^2, -6h, 2h^2], [-12, -6h, 12, -6h], [6h, 2h^2, -6h, 4h^2]]
//! M_e = rhoA h/420 [[156, 22h, 54, -13h], [22h, 4h^2, 13h, -3h^2], [54, 13h, 156, -22h],
//!                   [-13h, -3h^2, -22h, 4h^2]]
//! ```
//!
//! The natural frequencies converge to `(beta_k L)^2 sqrt(EI / (rhoA L^4))` with
//! `beta_k L = 1.8751, 4.6941, 7.8548, 10.9955, ...` (`cos(b) cosh(b) = -1`), at the rate
//! `h^4`. Dof `2n` is a massless pad joined to the tip deflection by a spring
//! `k_c = 10 x 3 EI / L^3` (ten times the static tip stiffness); a stop acts on the pad. A
//! massless pad carries no force when free, so the beam's frequencies are unchanged, and
//! the contact is well posed for every method (no impact law needed). The load is a uniform
//! transverse load of unit intensity (consistent nodal forces and moments).

use faer::sparse::Triplet;

use crate::cyclic::{CyclicSector, InvalidSector};
use crate::dynamic::UnionPattern;
use crate::model::{
    ContactPoint, ContactRow, FrictionPoint, HarmonicLoad, NeighbourRow, SparseMatrix,
    StructuralModel, Structure,
};
use crate::rod::{natural_frequencies, ModelError};

/// Mistuning amplitude of the shipped disk (`scenes/bladed_disk_casing.toml`).
pub const SHIPPED_MISTUNING: f64 = 0.02;

/// A bladed disk of `blades` sectors (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladedDisk {
    /// Number of sectors `B >= 1` (`3 B` dofs).
    pub blades: usize,
    /// Mistuning amplitude of the blade stiffnesses (0: tuned, cyclically symmetric).
    pub mistuning: f64,
}

/// How a [`BladedDisk`] is loaded, damped and stopped.
#[derive(Debug, Clone, PartialEq)]
pub struct DiskLoading {
    /// Blades (0-based) whose pad meets the casing.
    pub stops: Vec<usize>,
    /// Casing clearance of every stop.
    pub gap: f64,
    /// Load amplitude (times the unit blade-tip load shape).
    pub amplitude: f64,
    /// Stiffness-proportional damping `D = (2 zeta / omega_1) K`.
    pub zeta: f64,
    /// Forcing frequency in units of `omega_1` ([`DiskLoading::omega`]).
    pub omega_ratio: f64,
}

impl DiskLoading {
    /// The loading of the shipped disk scenes (`scenes/bladed_disk_casing.toml`): casing
    /// clearance 1 on the pads of `stops`, load amplitude 0.02, 1 % damping, forced at the
    /// tuned resonance.
    pub fn shipped(stops: Vec<usize>) -> Self {
        Self {
            stops,
            gap: 1.0,
            amplitude: 0.02,
            zeta: 0.01,
            omega_ratio: 1.0,
        }
    }

    /// The forcing frequency for a disk whose first natural frequency is `omega_1`
    /// ([`Structure::omega_1`] of [`BladedDisk::structure`]).
    pub fn omega(&self, omega_1: f64) -> f64 {
        self.omega_ratio * omega_1
    }
}

impl BladedDisk {
    /// The tuned disk of `blades` sectors (no mistuning: cyclically symmetric).
    pub fn tuned(blades: usize) -> Self {
        Self {
            blades,
            mistuning: 0.0,
        }
    }

    /// Number of dofs `3 B`.
    pub fn dofs(&self) -> usize {
        3 * self.blades
    }

    /// The pad dof (0-based) of blade `j`.
    pub fn pad(j: usize) -> usize {
        3 * j + 2
    }

    /// The blade tip dof (0-based) of blade `j`.
    pub fn tip(j: usize) -> usize {
        3 * j + 1
    }

    /// The deterministic mistuning `delta_j = mistuning sin(2.3 j)`, one per blade.
    pub fn deterministic_mistuning(&self) -> Vec<f64> {
        (0..self.blades)
            .map(|j| self.mistuning * (2.3 * j as f64).sin())
            .collect()
    }

    /// Stiffness, mass and load shape with the deterministic mistuning.
    pub fn matrices(&self) -> (SparseMatrix, SparseMatrix, Vec<f64>) {
        Self::mistuned_matrices(&self.deterministic_mistuning())
    }

    /// Stiffness, mass and load shape of the disk of `mistuning.len()` blades whose blade
    /// `j` has the stiffness `k_b (1 + mistuning[j])` (the caller keeps each above -1).
    pub fn mistuned_matrices(mistuning: &[f64]) -> (SparseMatrix, SparseMatrix, Vec<f64>) {
        let blades = mistuning.len();
        let n = 3 * blades;
        let (k_g, k_d, k_b, k_c) = (1.0, 1.0, 1.0, 10.0);
        let mut k = Vec::new();
        let mut spring = |i: usize, j: Option<usize>, s: f64| {
            k.push(Triplet::new(i, i, s));
            if let Some(j) = j {
                k.push(Triplet::new(j, j, s));
                k.push(Triplet::new(i, j, -s));
                k.push(Triplet::new(j, i, -s));
            }
        };
        for (j, delta) in mistuning.iter().enumerate() {
            let (d, b, p) = (3 * j, Self::tip(j), Self::pad(j));
            spring(d, None, k_g);
            if blades > 1 {
                spring(d, Some(3 * ((j + 1) % blades)), k_d);
            }
            spring(d, Some(b), k_b * (1.0 + delta));
            spring(b, Some(p), k_c);
        }
        let m: Vec<Triplet<usize, usize, f64>> = (0..n)
            .filter(|i| i % 3 != 2)
            .map(|i| Triplet::new(i, i, 1.0))
            .collect();
        let k = SparseMatrix::try_new_from_triplets(n, n, &k).expect("entries within 3B x 3B");
        let m = SparseMatrix::try_new_from_triplets(n, n, &m).expect("entries within 3B x 3B");
        let f = (0..n).map(|i| if i % 3 == 1 { 1.0 } else { 0.0 }).collect();
        (k, m, f)
    }

    /// The disk under `loading` with a Coulomb friction point on every blade's platform
    /// (its pad rubbing a fixed part, coefficient `mu`, constant `normal_load`), and its
    /// forcing frequency [`DiskLoading::omega`].
    pub fn with_platform_friction(
        &self,
        loading: &DiskLoading,
        mu: f64,
        normal_load: f64,
    ) -> Result<(Structure, f64), ModelError> {
        let mut structure = self.structure(loading)?;
        for j in 0..self.blades {
            let platform = ContactRow::unit(Self::pad(j), 1.0);
            structure
                .model
                .friction
                .push(FrictionPoint::prescribed(platform, mu, normal_load));
        }
        let omega = loading.omega(structure.omega_1);
        Ok((structure, omega))
    }

    /// The disk as a structure: `omega_1` its lowest natural frequency, the observed dof the
    /// first stop's pad (blade 0's tip without stops); its forcing frequency is
    /// [`DiskLoading::omega`]. A stop out of range or no blade is
    /// [`ModelError::InvalidParameter`].
    pub fn structure(&self, loading: &DiskLoading) -> Result<Structure, ModelError> {
        self.structure_with_mistuning(loading, &self.deterministic_mistuning())
    }

    /// [`BladedDisk::structure`] with blade `j`'s stiffness `k_b (1 + mistuning[j])` in
    /// place of the builder's pattern (one finite value above -1 per blade; `self.mistuning`
    /// is not used).
    pub fn structure_with_mistuning(
        &self,
        loading: &DiskLoading,
        mistuning: &[f64],
    ) -> Result<Structure, ModelError> {
        if mistuning.len() != self.blades {
            return Err(ModelError::InvalidParameter {
                name: "mistuning pattern length",
                value: mistuning.len() as f64,
                allowed: "one value per blade",
            });
        }
        if let Some(&delta) = mistuning.iter().find(|d| !(d.is_finite() && **d > -1.0)) {
            return Err(ModelError::InvalidParameter {
                name: "blade mistuning",
                value: delta,
                allowed: "finite and above -1 (a positive blade stiffness)",
            });
        }
        if self.blades == 0 {
            return Err(ModelError::InvalidParameter {
                name: "blades",
                value: 0.0,
                allowed: "at least 1",
            });
        }
        if let Some(&j) = loading.stops.iter().find(|&&j| j >= self.blades) {
            return Err(ModelError::InvalidParameter {
                name: "stop blade",
                value: j as f64,
                allowed: "a blade index below the number of blades",
            });
        }
        let (stiffness, mass, shape) = Self::mistuned_matrices(mistuning);
        let n = self.dofs();
        let mut model = StructuralModel {
            frictional_contacts: Vec::new(),
            mass,
            damping: None,
            stiffness,
            load: HarmonicLoad::cosine(shape.iter().map(|f| loading.amplitude * f).collect()),
            contacts: loading
                .stops
                .iter()
                .map(|&j| ContactPoint::new(Self::pad(j), loading.gap))
                .collect(),
            friction: Vec::new(),
            cyclic: None,
        };
        let omega_1 = natural_frequencies(&model, 1)?[0];
        model.damping = Some(UnionPattern::linear_combination(
            n,
            &[&model.stiffness],
            &[2.0 * loading.zeta / omega_1],
        ));
        let observed_dof = model.contacts.first().map_or(Self::tip(0), |c| c.dof());
        Ok(Structure {
            model,
            omega_1,
            observed_dof,
        })
    }
}

impl BladedDisk {
    /// The dofs `[d_j, b_j, p_j]` of each sector `j` (for [`HarmonicLoad::delayed_by_sector`]).
    pub fn sector_dofs(&self) -> Vec<Vec<usize>> {
        (0..self.blades)
            .map(|j| vec![3 * j, 3 * j + 1, 3 * j + 2])
            .collect()
    }

    /// The whole disk's harmonic-major coefficients (`3 B (2 H + 1)`, the layout of
    /// [`BladedDisk::structure`]) recovered from the reduced coefficients `reduced` of
    /// `sector` (one of [`BladedDisk::cyclic_sector`]): blade `j`'s `d, b, p` are sector
    /// `j`'s dofs 0, 1, 2 ([`CyclicSector::sector_coefficients`]).
    pub fn recover(&self, sector: &CyclicSector, reduced: &[f64], harmonics: usize) -> Vec<f64> {
        let n = self.dofs();
        let mut full = vec![0.0; n * (2 * harmonics + 1)];
        let sector_dofs = sector.model().dofs();
        for j in 0..self.blades {
            let u = sector.sector_coefficients(reduced, harmonics, j);
            for (row, block) in full.chunks_exact_mut(n).enumerate() {
                block[3 * j..3 * j + 3].copy_from_slice(&u[row * sector_dofs..][..3]);
            }
        }
        full
    }

    /// The whole disk's harmonic-balance unknowns `[U; Lambda]` recovered from a sector's
    /// solution `state` (`[U_r; Lambda_r]`, [`crate::solve::Solution::state`]): `U` by
    /// [`BladedDisk::recover`], and row `r` of blade `j` (full row `r B + j`: every
    /// blade's copy of the sector's row 0, then of row 1, ...) the sector's row `r` delayed
    /// by `j EO T / N`. A warm start for the full disk at the same frequency.
    pub fn recover_state(
        &self,
        sector: &CyclicSector,
        state: &[f64],
        harmonics: usize,
    ) -> Vec<f64> {
        let size = 2 * harmonics + 1;
        let (u, lambda) = state.split_at(sector.reduced_dofs().len() * size);
        let mut full = self.recover(sector, u, harmonics);
        let rows = lambda.len() / size;
        let mut forces = vec![0.0; rows * self.blades * size];
        for j in 0..self.blades {
            let mut delayed = lambda.to_vec();
            let angle = j as f64 * sector.phase_step();
            crate::cyclic::delay_coefficients(&mut delayed, rows, harmonics, angle);
            for (h, block) in delayed.chunks_exact(rows).enumerate() {
                for (r, &value) in block.iter().enumerate() {
                    forces[h * rows * self.blades + r * self.blades + j] = value;
                }
            }
        }
        full.extend(forces);
        full
    }

    /// One sector of the tuned disk (the mistuning is ignored) under `loading` and the
    /// engine order `engine_order`, with the lowest natural frequency `omega_1` of the disk
    /// that scales its damping ([`CyclicSector::lowest_frequency`]). The sector's dofs are `d, b, p` of blade 0
    /// and the next sector's disk dof `d'` (3, the right interface of the left dof 0): the
    /// ground, blade and pad springs and the ring spring `d - d'`, unit masses on `d`, `b`.
    /// Cyclic symmetry needs a stop on every blade or on none: its pad meets the casing
    /// when `loading.stops` lists every blade, and other stops are
    /// [`ModelError::InvalidParameter`].
    pub fn cyclic_sector(
        &self,
        loading: &DiskLoading,
        engine_order: usize,
    ) -> Result<(CyclicSector, f64), ModelError> {
        let mut stops = loading.stops.clone();
        stops.sort_unstable();
        stops.dedup();
        if self.blades == 0 || !(stops.is_empty() || stops == (0..self.blades).collect::<Vec<_>>())
        {
            return Err(ModelError::InvalidParameter {
                name: "stop blades of a cyclic sector",
                value: stops.len() as f64,
                allowed: "every blade of a disk of at least one blade, or none",
            });
        }
        let (k_g, k_d, k_b, k_c) = (1.0, 1.0, 1.0, 10.0);
        let mut t = vec![Triplet::new(0, 0, k_g)];
        for (i, j, s) in [(0, 3, k_d), (0, 1, k_b), (1, 2, k_c)] {
            t.extend([
                Triplet::new(i, i, s),
                Triplet::new(j, j, s),
                Triplet::new(i, j, -s),
                Triplet::new(j, i, -s),
            ]);
        }
        let stiffness =
            SparseMatrix::try_new_from_triplets(4, 4, &t).expect("entries within 4 x 4");
        let mass = [Triplet::new(0, 0, 1.0), Triplet::new(1, 1, 1.0)];
        let mass = SparseMatrix::try_new_from_triplets(4, 4, &mass).expect("entries within 4 x 4");
        let mut model =
            StructuralModel::new(mass, stiffness, vec![0.0, loading.amplitude, 0.0, 0.0]);
        if !stops.is_empty() {
            model = model.with_contact(ContactPoint::new(Self::pad(0), loading.gap));
        }
        let sector = |model| {
            // The sector's interfaces and rows are valid by construction: only a
            // non-finite gap, amplitude or damping is left to refuse.
            CyclicSector::new(model, vec![0], vec![3], self.blades, engine_order).map_err(|_| {
                ModelError::InvalidParameter {
                    name: "disk loading",
                    value: f64::NAN,
                    allowed: "a finite gap, load amplitude and damping ratio",
                }
            })
        };
        let omega_1 = sector(model.clone())?.lowest_frequency()?;
        let model = model.with_rayleigh_damping(0.0, 2.0 * loading.zeta / omega_1);
        Ok((sector(model)?, omega_1))
    }
}

/// An under-platform damper between neighbouring blades of a [`BladedDisk`]: blade `j`'s
/// pad against the mean of the next blade's tip and disk dof,
/// `p_j - (b_{j+1} + d_{j+1}) / 2 - gap <= 0`, with Coulomb friction `friction` (the
/// damper's normal force; none at 0) on the slip `b_j - d_{j+1}`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeDamper {
    /// Clearance of the damper.
    pub gap: f64,
    /// Coulomb coefficient `mu >= 0`.
    pub friction: f64,
}

impl BladeDamper {
    /// The damper between every pair of neighbours of the whole disk `disk` added to its
    /// `model` (contacts blade by blade, then their friction rows).
    pub fn add_to_disk(&self, disk: &BladedDisk, model: &mut StructuralModel) {
        let first = model.contacts.len();
        let blades = disk.blades;
        for j in 0..blades {
            let next = 3 * ((j + 1) % blades);
            let row = ContactRow::new(vec![3 * j + 2, next + 1, next], vec![1.0, -0.5, -0.5]);
            (model.contacts).push(ContactPoint::on_row(row.expect("a valid row"), self.gap));
        }
        for j in (0..blades).filter(|_| self.friction > 0.0) {
            let next = 3 * ((j + 1) % blades);
            let slip = ContactRow::new(vec![3 * j + 1, next], vec![1.0, -1.0]);
            let point =
                FrictionPoint::on_contact(slip.expect("a valid row"), self.friction, first + j);
            model.friction.push(point);
        }
    }

    /// The damper on the sector `sector` of [`BladedDisk::cyclic_sector`]: its own part on
    /// the pad (and tip), its neighbour part on the next sector's tip and disk dof.
    pub fn add_to_sector(&self, sector: &CyclicSector) -> Result<CyclicSector, InvalidSector> {
        let mut model = sector.model().clone();
        let contact = model.contacts.len();
        model
            .contacts
            .push(ContactPoint::on_row(ContactRow::unit(2, 1.0), self.gap));
        let part = ContactRow::new(vec![1, 0], vec![-0.5, -0.5]).expect("a valid row");
        let mut rows = sector.neighbour_rows().to_vec();
        rows.push(NeighbourRow { row: contact, part });
        if self.friction > 0.0 {
            let tangent = ContactRow::unit(1, 1.0);
            model
                .friction
                .push(FrictionPoint::on_contact(tangent, self.friction, contact));
            let row = model.contacts.len() + model.friction.len() - 1;
            rows.push(NeighbourRow {
                row,
                part: ContactRow::unit(0, -1.0),
            });
        }
        let (left, right) = (sector.left().to_vec(), sector.right().to_vec());
        CyclicSector::new(model, left, right, sector.sectors(), sector.engine_order())?
            .with_neighbour_rows(rows)
    }
}

/// The pad's spring, relative to the static tip stiffness `3 EI / L^3`.
pub const PAD_STIFFNESS_FACTOR: f64 = 10.0;

/// Stiffness, mass and unit uniform load of the `elements`-element cantilever with a tip
/// pad (`2 elements + 1` dofs; module documentation).
pub fn cantilever_with_tip_pad(elements: usize) -> (SparseMatrix, SparseMatrix, Vec<f64>) {
    let h = 1.0 / elements as f64;
    let n = 2 * elements + 1;
    let ke = {
        let c = 1.0 / (h * h * h);
        [
            [12.0, 6.0 * h, -12.0, 6.0 * h],
            [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
            [-12.0, -6.0 * h, 12.0, -6.0 * h],
            [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
        ]
        .map(|row| row.map(|v| c * v))
    };
    let me = {
        let c = h / 420.0;
        [
            [156.0, 22.0 * h, 54.0, -13.0 * h],
            [22.0 * h, 4.0 * h * h, 13.0 * h, -3.0 * h * h],
            [54.0, 13.0 * h, 156.0, -22.0 * h],
            [-13.0 * h, -3.0 * h * h, -22.0 * h, 4.0 * h * h],
        ]
        .map(|row| row.map(|v| c * v))
    };
    // Uniform load q = 1: nodal forces q h / 2 and moments +-q h^2 / 12.
    let fe = [h / 2.0, h * h / 12.0, h / 2.0, -h * h / 12.0];
    let (mut k, mut m) = (Vec::new(), Vec::new());
    let mut f = vec![0.0; n];
    for e in 0..elements {
        // Element e joins nodes e and e + 1; node i >= 1 has dofs 2(i - 1), 2(i - 1) + 1.
        let dofs: [Option<usize>; 4] = if e == 0 {
            [None, None, Some(0), Some(1)]
        } else {
            [
                Some(2 * e - 2),
                Some(2 * e - 1),
                Some(2 * e),
                Some(2 * e + 1),
            ]
        };
        for a in 0..4 {
            let Some(i) = dofs[a] else { continue };
            f[i] += fe[a];
            for b in 0..4 {
                let Some(j) = dofs[b] else { continue };
                k.push(Triplet::new(i, j, ke[a][b]));
                m.push(Triplet::new(i, j, me[a][b]));
            }
        }
    }
    let (tip, pad) = (2 * elements - 2, 2 * elements);
    let kc = PAD_STIFFNESS_FACTOR * 3.0;
    for (i, j, v) in [
        (tip, tip, kc),
        (tip, pad, -kc),
        (pad, tip, -kc),
        (pad, pad, kc),
    ] {
        k.push(Triplet::new(i, j, v));
    }
    let k = SparseMatrix::try_new_from_triplets(n, n, &k).expect("entries within the dofs");
    let m = SparseMatrix::try_new_from_triplets(n, n, &m).expect("entries within the dofs");
    (k, m, f)
}

/// [`cantilever_with_tip_pad`] with the pad's spring `pad_stiffness` (finite, `> 0`) in
/// place of `10 x 3 EI / L^3`: a Coulomb slider holding the pad makes a Jenkins element of
/// that stiffness on the tip deflection (dof `2 elements - 2`; the pad is dof
/// `2 elements`).
pub fn cantilever_with_tip_spring(
    elements: usize,
    pad_stiffness: f64,
) -> (SparseMatrix, SparseMatrix, Vec<f64>) {
    let (k, m, f) = cantilever_with_tip_pad(elements);
    let n = k.nrows();
    let (tip, pad) = (2 * elements - 2, 2 * elements);
    let change = pad_stiffness - PAD_STIFFNESS_FACTOR * 3.0;
    let mut entries = Vec::with_capacity(k.compute_nnz() + 4);
    let kr = k.as_ref();
    for j in 0..n {
        for (i, v) in kr.row_idx_of_col(j).zip(kr.val_of_col(j)) {
            entries.push(Triplet::new(i, j, *v));
        }
    }
    for (i, j, sign) in [
        (tip, tip, 1.0),
        (tip, pad, -1.0),
        (pad, tip, -1.0),
        (pad, pad, 1.0),
    ] {
        entries.push(Triplet::new(i, j, sign * change));
    }
    let k = SparseMatrix::try_new_from_triplets(n, n, &entries).expect("entries within the dofs");
    (k, m, f)
}
