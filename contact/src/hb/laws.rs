//! The contact laws in harmonic balance: each row group's law sampled through the AFT
//! (sample its arguments, apply the law, project back), and the pattern of the contact
//! Jacobian's blocks.
//!
//! For a group owning rows `a = 0..k` and reading rows `s`, with the arguments
//! `z_a = lambda_a - c (y_a - o_a)` ([`crate::law`]), the Galerkin residual is
//! `R_a = Lambda_a - P proj_a(E z, E Lambda_read)`, and its generalized Jacobian
//! `dR_a/dLambda_b = [a = b] I - Q_ab`, `dR_a/dU = c Q_ab M_b G_b`,
//! `dR_a/dLambda_s = X_as` with `Q_ab = P diag(d proj_a / d z_b) E`,
//! `X_as = -P diag(d proj_a / d r_s) E` (`M_b` the measure of row `b`: identity, or the
//! phase derivative of a slip row). `Q` is block diagonal by group; the blocks are stored
//! flat, group after group, in the order of [`LawLayout::q_pairs`] and
//! [`LawLayout::x_pairs`].

use std::sync::Arc;

use faer::{Mat, MatMut};
use semismooth::harmonic::Aft;
use semismooth::linalg::LinearSolveError;
use semismooth::InvalidOption;

use super::{HbError, LinearData};
use crate::law::{ContactLaw, Coulomb, FrictionDisk, LawGroup, LawSamples, Measure, Unilateral};
use crate::model::{NormalForce, NormalLaw, StructuralModel};

/// One group of rows of `G` and its law.
#[derive(Debug, Clone)]
pub(crate) struct RowGroup {
    /// Its first row (its rows are `first..first + law.rows()`).
    pub(crate) first: usize,
    pub(crate) law: Arc<dyn ContactLaw>,
    /// Index of its block `Q_00` in the Jacobian's `Q` blocks.
    q_first: usize,
    /// Index of its block `X_00` in the Jacobian's `X` blocks.
    x_first: usize,
}

/// The row groups of a model and the pattern of their Jacobian blocks.
#[derive(Debug, Clone)]
pub(crate) struct LawLayout {
    pub(crate) groups: Vec<RowGroup>,
    /// `(a, b)`: the rows of each `Q` block.
    pub(crate) q_pairs: Vec<(usize, usize)>,
    /// `(a, s)`: the row and the row read of each `X` block.
    pub(crate) x_pairs: Vec<(usize, usize)>,
    /// The group of each friction point (one tangential row, its group's `first`).
    pub(crate) friction_groups: Vec<usize>,
    /// The index of `Q_aa` of each row.
    pub(crate) diagonal: Vec<usize>,
    /// The index in `groups` of each row's group.
    group_of_row: Vec<usize>,
    /// Whether each row measures a slip velocity.
    pub(crate) velocity: Vec<bool>,
    /// The rows that measure a slip velocity.
    pub(crate) velocity_rows: Vec<usize>,
    /// The offset `o_a` of each row in its law's argument.
    pub(crate) offsets: Vec<f64>,
    /// The offsets' `(cos, sin)` coefficients on harmonics 1, 2, ... of each row (a moving
    /// obstacle's gap; empty for most rows).
    pub(crate) offset_harmonics: Vec<Vec<(f64, f64)>>,
    /// The obstacle's sliding velocity `s_a` of each slip row (0 for most rows): its offset
    /// is `s_a / w`, the velocity per radian.
    pub(crate) sliding: Vec<f64>,
}

impl LawLayout {
    /// The groups of `model` (a [`Unilateral`] law per contact, a [`Coulomb`] law per
    /// friction point, a [`Unilateral`] law on the normal row, if any, and a
    /// [`FrictionDisk`] on the tangent rows per frictional contact) followed by `added`
    /// (validated against the `dofs` and the rows).
    pub(crate) fn new(
        model: &StructuralModel,
        added: &[LawGroup],
        dofs: usize,
    ) -> Result<Self, HbError> {
        let mut laws: Vec<(Arc<dyn ContactLaw>, Vec<f64>)> = Vec::new();
        for contact in &model.contacts {
            laws.push((Arc::new(Unilateral), vec![contact.gap]));
        }
        let mut friction_groups = Vec::with_capacity(model.friction.len());
        for point in &model.friction {
            friction_groups.push(laws.len());
            laws.push((
                Arc::new(Coulomb::new(point.coefficient, point.normal)),
                vec![0.0],
            ));
        }
        let mut row = model.contacts.len() + model.friction.len();
        let (mut moving, mut sliding) = (Vec::new(), Vec::new());
        for point in &model.frictional_contacts {
            let normal = match point.normal {
                NormalLaw::Unilateral { gap, .. } => {
                    laws.push((Arc::new(Unilateral), vec![gap]));
                    moving.push((row, point.gap_harmonics()));
                    row += 1;
                    NormalForce::Contact(row - 1)
                }
                NormalLaw::Prescribed(load) => NormalForce::Prescribed(load),
            };
            laws.push((
                Arc::new(FrictionDisk::new(point.coefficient, normal)),
                vec![0.0, 0.0],
            ));
            sliding.push((row, point.sliding_velocity));
            row += 2;
        }
        let own = row;
        let total = own + added.iter().map(|g| g.rows.len()).sum::<usize>();
        let mut first = own;
        for group in added {
            validate_group(group, first, total, dofs)?;
            first += group.rows.len();
            laws.push((group.law.clone(), group.offsets.clone()));
        }
        let mut layout = Self {
            groups: Vec::with_capacity(laws.len()),
            q_pairs: Vec::new(),
            x_pairs: Vec::new(),
            friction_groups,
            diagonal: Vec::with_capacity(total),
            group_of_row: Vec::with_capacity(total),
            velocity: Vec::with_capacity(total),
            velocity_rows: Vec::new(),
            offsets: Vec::with_capacity(total),
            offset_harmonics: vec![Vec::new(); total],
            sliding: vec![0.0; total],
        };
        for (law, offsets) in laws {
            layout.push(law, offsets);
        }
        for (row, harmonics) in moving {
            layout.offset_harmonics[row] = harmonics;
        }
        for (row, velocity) in sliding {
            layout.sliding[row..row + 2].copy_from_slice(&velocity);
        }
        Ok(layout)
    }

    /// The polyalgorithm's smoothing scale `mu_0` for the penalty `c` (see
    /// `semismooth::Smoothing`): the larger of `c e` with `e` the gaps' extent `max_a
    /// reach_a` and the largest slip limit under a prescribed load. Without `linear`, a
    /// row's reach is its gap `|o_a|`; with the measured coefficients `y` of the response
    /// with every contact force zero (index `j m + a`), `min(|o_a|, sum_j |y_ja|)` where that
    /// sum is positive: a stop beyond that motion is blurred only over the motion.
    pub(crate) fn smoothing_scale(&self, c: f64, linear: Option<&[f64]>) -> f64 {
        let m = self.offsets.len();
        let within = |row: usize, gap: f64| {
            let reach: f64 =
                linear.map_or(0.0, |y| y[row..].iter().step_by(m).map(|v| v.abs()).sum());
            if reach > 0.0 {
                gap.min(reach)
            } else {
                gap
            }
        };
        let extent = (self.offsets.iter().enumerate())
            .filter(|(_, o)| **o != 0.0)
            .fold(0.0f64, |a, (row, o)| a.max(within(row, o.abs())));
        // A friction point under a prescribed load switches at its slip limit.
        let force = (self.groups.iter()).fold(0.0, |a, group| group.law.force_scale().max(a));
        (c * extent.max(f64::MIN_POSITIVE)).max(force)
    }

    fn push(&mut self, law: Arc<dyn ContactLaw>, offsets: Vec<f64>) {
        let first = self.velocity.len();
        let (k, velocity) = (law.rows(), law.measure() == Measure::Velocity);
        let (q_first, x_first) = (self.q_pairs.len(), self.x_pairs.len());
        for a in first..first + k {
            for b in first..first + k {
                if a == b {
                    self.diagonal.push(self.q_pairs.len());
                }
                self.q_pairs.push((a, b));
            }
            self.x_pairs.extend(law.reads().iter().map(|&s| (a, s)));
            self.velocity.push(velocity);
            self.group_of_row.push(self.groups.len());
            if velocity {
                self.velocity_rows.push(a);
            }
        }
        self.offsets.extend(offsets);
        self.groups.push(RowGroup {
            first,
            law,
            q_first,
            x_first,
        });
    }

    /// The group owning row `a` and `a`'s index in it.
    fn group_of(&self, a: usize) -> Option<(&RowGroup, usize)> {
        let group = &self.groups[*self.group_of_row.get(a)?];
        Some((group, a - group.first))
    }

    /// The index of the block `Q_ab` (rows `a`, `b` of one group), if there is one.
    pub(crate) fn q_block(&self, a: usize, b: usize) -> Option<usize> {
        let (group, local) = self.group_of(a)?;
        let k = group.law.rows();
        let other = b.checked_sub(group.first).filter(|&b| b < k)?;
        Some(group.q_first + local * k + other)
    }

    /// The index of the block `X_as` (row `a`'s law reading row `s`), if there is one.
    pub(crate) fn x_block(&self, a: usize, s: usize) -> Option<usize> {
        let (group, local) = self.group_of(a)?;
        let reads = group.law.reads();
        let read = reads.iter().position(|&r| r == s)?;
        Some(group.x_first + local * reads.len() + read)
    }

    /// Coefficient `j` (`[a_0, a_1, b_1, a_2, b_2, ...]`) of row `row`'s offset `o_a`: the
    /// constant offset, then the moving obstacle's harmonics (0 beyond them).
    pub(crate) fn offset_coefficient(&self, row: usize, j: usize) -> f64 {
        match j {
            0 => self.offsets[row],
            j => self.offset_harmonics[row]
                .get((j - 1) / 2)
                .map_or(0.0, |(a, b)| if j % 2 == 1 { *a } else { *b }),
        }
    }

    /// `(2H + 1)`-square zero blocks for every `Q` block and every `X` block.
    pub(crate) fn zero_blocks(&self, size: usize) -> (Vec<Mat<f64>>, Vec<Mat<f64>>) {
        let zeros = |count: usize| (0..count).map(|_| Mat::zeros(size, size)).collect();
        (zeros(self.q_pairs.len()), zeros(self.x_pairs.len()))
    }

    /// `out = Q p` (index `j m + row`).
    pub(crate) fn apply_q(&self, q: &[Mat<f64>], m: usize, p: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (block, &(a, b)) in q.iter().zip(&self.q_pairs) {
            // Column by column (contiguous), each sum accumulated in the order of l.
            for l in 0..block.ncols() {
                let pl = p[l * m + b];
                if pl == 0.0 {
                    continue;
                }
                for (o, v) in out[a..].iter_mut().step_by(m).zip(block.col_as_slice(l)) {
                    *o += v * pl;
                }
            }
        }
    }

    /// `out += X p` (index `j m + row`).
    pub(crate) fn apply_x_add(&self, x: &[Mat<f64>], m: usize, p: &[f64], out: &mut [f64]) {
        for (block, &(a, s)) in x.iter().zip(&self.x_pairs) {
            for l in 0..block.ncols() {
                let pl = p[l * m + s];
                if pl == 0.0 {
                    continue;
                }
                for (j, v) in block.col_as_slice(l).iter().enumerate() {
                    out[j * m + a] += v * pl;
                }
            }
        }
    }

    /// `S[(j m + a, l m + s)] += X_as[j, l]` for every `X` block.
    pub(crate) fn add_x_dense(&self, x: &[Mat<f64>], m: usize, mut out: MatMut<'_, f64>) {
        for (block, &(a, s)) in x.iter().zip(&self.x_pairs) {
            for l in 0..block.ncols() {
                for (j, v) in block.col_as_slice(l).iter().enumerate() {
                    out[(j * m + a, l * m + s)] += v;
                }
            }
        }
    }
}

/// Copies the blocks `source` into `blocks` (a non-finite entry is an error, its column
/// counted from the first block's).
pub(crate) fn copy_blocks(
    blocks: &mut [Mat<f64>],
    source: &[Mat<f64>],
) -> Result<(), LinearSolveError> {
    for (i, (block, from)) in blocks.iter_mut().zip(source).enumerate() {
        block.copy_from(from);
        for col in 0..block.ncols() {
            let column = block.col_as_slice(col);
            if let Some((row, &value)) = column.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                let col = i * block.ncols() + col;
                return Err(LinearSolveError::NonFiniteEntry { row, col, value });
            }
        }
    }
    Ok(())
}

/// `Err` unless `group` has one offset per row, as many rows as its law, rows on existing
/// dofs, finite offsets and reads of existing rows outside its own (`first..`).
fn validate_group(
    group: &LawGroup,
    first: usize,
    total: usize,
    dofs: usize,
) -> Result<(), HbError> {
    let k = group.rows.len();
    let mismatch = |what, expected, found| HbError::DimensionMismatch {
        what,
        expected,
        found,
    };
    if k == 0 || group.law.rows() != k {
        return Err(mismatch("rows of a law group", group.law.rows(), k));
    }
    if group.offsets.len() != k {
        return Err(mismatch("offsets of a law group", k, group.offsets.len()));
    }
    for offset in &group.offsets {
        InvalidOption::check(offset.is_finite(), "law offset", *offset, "a finite number")?;
    }
    for (dof, _) in group.rows.iter().flat_map(|row| row.entries()) {
        super::check_index("dof of a law group's row", dof, dofs)?;
    }
    for &read in group.law.reads() {
        super::check_index("row read by a law", read, total)?;
        if (first..first + k).contains(&read) {
            return Err(HbError::IndexOutOfRange {
                what: "row read by a law (its own rows are not read)",
                index: read,
                count: total,
            });
        }
    }
    Ok(())
}

/// Sample buffers of the laws (sized for the widest group): the arguments, the forces
/// read, the law's values and Jacobian blocks.
#[derive(Debug, Clone, Default)]
pub(crate) struct LawSampler {
    z: Vec<f64>,
    read: Vec<f64>,
    value: Vec<f64>,
    dz: Vec<f64>,
    dread: Vec<f64>,
}

impl LawSampler {
    pub(crate) fn new(lin: &LinearData) -> Self {
        let nt = lin.basis.time_samples();
        let (mut rows, mut reads) = (0, 0);
        for group in &lin.laws.groups {
            rows = rows.max(group.law.rows());
            reads = reads.max(group.law.reads().len());
        }
        Self {
            z: vec![0.0; rows * nt],
            read: vec![0.0; reads * nt],
            value: vec![0.0; rows * nt],
            dz: vec![0.0; rows * rows * nt],
            dread: vec![0.0; rows * reads * nt],
        }
    }

    /// Samples group `g`'s arguments `z_a = lambda_a - c (y_a - o_a)` and the forces it
    /// reads at the frequency `omega`: `forces` the rows' force coefficients (index
    /// `j m + row`), `measured(row, j)` coefficient `j` of the row's measured quantity `y`.
    pub(crate) fn sample(
        &mut self,
        aft: &mut Aft,
        lin: &LinearData,
        (g, c, omega): (usize, f64, f64),
        forces: &[f64],
        measured: impl Fn(usize, usize) -> f64,
    ) {
        let (m, nt) = (lin.contacts(), lin.basis.time_samples());
        let group = &lin.laws.groups[g];
        for a in 0..group.law.rows() {
            let row = group.first + a;
            let coeffs = aft.coefficients_mut();
            for (j, coeff) in coeffs.iter_mut().enumerate() {
                *coeff = forces[j * m + row] - c * measured(row, j);
            }
            coeffs[0] += c * (lin.laws.offsets[row] + lin.laws.sliding[row] / omega);
            let moving = 2 * lin.laws.offset_harmonics[row].len();
            for (j, coeff) in coeffs.iter_mut().enumerate().take(moving + 1).skip(1) {
                *coeff += c * lin.laws.offset_coefficient(row, j);
            }
            aft.coefficients_to_samples();
            self.z[a * nt..(a + 1) * nt].copy_from_slice(aft.samples());
        }
        for (s, &read) in group.law.reads().iter().enumerate() {
            for (j, coeff) in aft.coefficients_mut().iter_mut().enumerate() {
                *coeff = forces[j * m + read];
            }
            aft.coefficients_to_samples();
            self.read[s * nt..(s + 1) * nt].copy_from_slice(aft.samples());
        }
    }

    fn at(&self, lin: &LinearData, g: usize, smoothing: f64) -> LawSamples<'_> {
        let group = &lin.laws.groups[g];
        let nt = lin.basis.time_samples();
        LawSamples {
            z: &self.z[..group.law.rows() * nt],
            read: &self.read[..group.law.reads().len() * nt],
            samples: nt,
            smoothing,
        }
    }

    /// `out[j m + a] = equation(j m + a, P_j proj_a)` for the rows `a` of group `g` at its
    /// sampled arguments, `proj` mapped by `law` (the projection or its `mu`-derivative).
    fn project_rows(
        &mut self,
        aft: &mut Aft,
        lin: &LinearData,
        (g, mu): (usize, f64),
        law: fn(&dyn ContactLaw, &LawSamples<'_>, &mut [f64]),
        out: &mut [f64],
        equation: impl Fn(usize, f64) -> f64,
    ) {
        let (m, nt) = (lin.contacts(), lin.basis.time_samples());
        let group = &lin.laws.groups[g];
        let k = group.law.rows();
        let mut value = std::mem::take(&mut self.value);
        law(
            group.law.as_ref(),
            &self.at(lin, g, mu),
            &mut value[..k * nt],
        );
        for a in 0..k {
            let row = group.first + a;
            aft.samples_mut()
                .copy_from_slice(&value[a * nt..(a + 1) * nt]);
            aft.samples_to_coefficients();
            for (j, p) in aft.coefficients().iter().enumerate() {
                out[j * m + row] = equation(j * m + row, *p);
            }
        }
        self.value = value;
    }

    /// `out[j m + a] = Lambda_a - P proj_a` for the rows of group `g` (sampled first).
    pub(crate) fn residual(
        &mut self,
        aft: &mut Aft,
        lin: &LinearData,
        (g, mu): (usize, f64),
        forces: &[f64],
        out: &mut [f64],
    ) {
        let project = |law: &dyn ContactLaw, at: &LawSamples<'_>, out: &mut [f64]| {
            law.project(at, out);
        };
        self.project_rows(aft, lin, (g, mu), project, out, |i, p| forces[i] - p);
    }

    /// `out[j m + a] = -P d proj_a / d mu` for the rows of group `g` (sampled first).
    pub(crate) fn smoothing_derivative(
        &mut self,
        aft: &mut Aft,
        lin: &LinearData,
        (g, mu): (usize, f64),
        out: &mut [f64],
    ) {
        let derivative = |law: &dyn ContactLaw, at: &LawSamples<'_>, out: &mut [f64]| {
            law.smoothing_derivative(at, out);
        };
        self.project_rows(aft, lin, (g, mu), derivative, out, |_, p| -p);
    }

    /// Group `g`'s blocks `Q_ab = P diag(d proj_a / d z_b) E` into `q` and
    /// `X_as = -P diag(d proj_a / d r_s) E` into `x` (sampled first); `active[a]` counts
    /// the samples of row `a` whose weight `d proj_a / d z_a` exceeds 1/2.
    pub(crate) fn jacobian(
        &mut self,
        aft: &mut Aft,
        lin: &LinearData,
        (g, mu): (usize, f64),
        (q, x): (&mut [Mat<f64>], &mut [Mat<f64>]),
        active: &mut [usize],
    ) {
        let nt = lin.basis.time_samples();
        let group = &lin.laws.groups[g];
        let (k, r) = self.law_jacobian(lin, (g, mu));
        for (block, weights) in self.dz[..k * k * nt].chunks_exact(nt).enumerate() {
            let (a, b) = (block / k, block % k);
            if a == b {
                active[group.first + a] = weights.iter().filter(|w| **w > 0.5).count();
            }
            aft.samples_mut().copy_from_slice(weights);
            aft.samples_multiplication_matrix(&mut q[group.q_first + block]);
        }
        for (block, weights) in self.dread[..k * r * nt].chunks_exact(nt).enumerate() {
            for (s, w) in aft.samples_mut().iter_mut().zip(weights) {
                *s = -w;
            }
            aft.samples_multiplication_matrix(&mut x[group.x_first + block]);
        }
    }

    /// Group `g`'s law's Jacobian at its sampled arguments into `dz` and `dread`; returns
    /// its rows and reads `(k, r)`.
    fn law_jacobian(&mut self, lin: &LinearData, (g, mu): (usize, f64)) -> (usize, usize) {
        let nt = lin.basis.time_samples();
        let law = &lin.laws.groups[g].law;
        let (k, r) = (law.rows(), law.reads().len());
        let at = LawSamples {
            z: &self.z[..k * nt],
            read: &self.read[..r * nt],
            samples: nt,
            smoothing: mu,
        };
        law.jacobian(
            &at,
            &mut self.dz[..k * k * nt],
            &mut self.dread[..k * r * nt],
        );
        (k, r)
    }

    /// `out[j m + a] = c P sum_b diag(d proj_a / d z_b) E dy_b` for the rows of group `g`
    /// (sampled first): how the residual moves when the measured quantities move by `dy`
    /// (`dy(row, j)` its coefficients) with the forces fixed.
    pub(crate) fn measured_response(
        &mut self,
        aft: &mut Aft,
        lin: &LinearData,
        (g, c, mu): (usize, f64, f64),
        dy: impl Fn(usize, usize) -> f64,
        out: &mut [f64],
    ) {
        let (m, nt) = (lin.contacts(), lin.basis.time_samples());
        let group = &lin.laws.groups[g];
        let (k, _) = self.law_jacobian(lin, (g, mu));
        let dz = &self.dz;
        // E (c dy_b) of every row b into `value`.
        let mut moved = std::mem::take(&mut self.value);
        for b in 0..k {
            for (j, coeff) in aft.coefficients_mut().iter_mut().enumerate() {
                *coeff = c * dy(group.first + b, j);
            }
            aft.coefficients_to_samples();
            moved[b * nt..(b + 1) * nt].copy_from_slice(aft.samples());
        }
        for a in 0..k {
            let samples = aft.samples_mut();
            for (n, s) in samples.iter_mut().enumerate() {
                *s = moved[n] * dz[a * k * nt + n];
                for b in 1..k {
                    *s += moved[b * nt + n] * dz[(a * k + b) * nt + n];
                }
            }
            aft.samples_to_coefficients();
            for (j, p) in aft.coefficients().iter().enumerate() {
                out[j * m + group.first + a] = *p;
            }
        }
        self.value = moved;
    }
}
