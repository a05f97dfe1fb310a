//! The one-step schemes of the time-marching reference (module documentation of
//! [`super`]): the iteration matrix factored once, the per-step contact LCP by Lemke.

mod tangent;

use std::f64::consts::PI;

use faer::Mat;
use semismooth::lemke::{Lemke, LemkeError, LemkeOptions, LemkeTermination};
use semismooth::linalg::FaerSparseLu;
use semismooth::InvalidOption;
use semismooth::{Factorize, LinearSolve};

use super::friction::CoulombStep;
use super::load::SampledLoad;
use super::{
    column_max_abs, resolve_scheme, MarchCounters, MarchError, MarchOptions, MarchScheme,
    MarchState,
};
use crate::dynamic::UnionPattern;
use crate::model::{check_omega, sparse_mul_add, SparseMatrix, StructuralModel};

/// A dof of a contact row (or of a friction point's tangential row) that carries mass, if
/// any.
pub(super) fn massive_contact_dof(model: &StructuralModel, massless: &[bool]) -> Option<usize> {
    model
        .rows()
        .flat_map(|row| row.dofs().iter().copied())
        .find(|&dof| !massless[dof])
}

/// `v -= g (g . v) / (g . g)` on the entries of the row `g` (`entry(v, dof)` is the
/// entry of dof `dof`): the motion along the row removed (a closed contact's massless dofs
/// at rest; for a one-dof row its velocity set to 0).
pub(super) fn remove_row_component<V: ?Sized>(
    row: &crate::model::ContactRow,
    v: &mut V,
    entry: impl Fn(&mut V, usize) -> &mut f64,
) {
    let (mut along, mut norm) = (0.0, 0.0);
    for (dof, a) in row.entries() {
        along += a * *entry(v, dof);
        norm += a * a;
    }
    for (dof, a) in row.entries() {
        *entry(v, dof) -= a * along / norm;
    }
}

/// The scheme actually marched (`Auto` resolved).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Scheme {
    Trapezoidal,
    MoreauJean { theta: f64, restitution: f64 },
}

impl Scheme {
    fn resolve(model: &StructuralModel, scheme: MarchScheme) -> Self {
        match resolve_scheme(model, scheme) {
            MarchScheme::MoreauJean { theta, restitution } => {
                Self::MoreauJean { theta, restitution }
            }
            MarchScheme::MasslessContactTrapezoidal | MarchScheme::Auto => Self::Trapezoidal,
        }
    }

    fn public(self) -> MarchScheme {
        match self {
            Self::Trapezoidal => MarchScheme::MasslessContactTrapezoidal,
            Self::MoreauJean { theta, restitution } => {
                MarchScheme::MoreauJean { theta, restitution }
            }
        }
    }

    /// Name of the iteration matrix.
    fn matrix(self) -> &'static str {
        match self {
            Self::Trapezoidal => "K_eff",
            Self::MoreauJean { .. } => "M_hat",
        }
    }
}

/// Lemke workspaces, one per LCP size (so varying active sets never reallocate), and a
/// dense buffer for the active block of `W`.
struct ContactLcp {
    lemke: Vec<Lemke>,
    options: LemkeOptions,
    block: Mat<f64>,
}

impl ContactLcp {
    fn new(m: usize) -> Self {
        Self {
            lemke: (0..=m).map(Lemke::new).collect(),
            options: LemkeOptions::default(),
            block: Mat::zeros(m, m),
        }
    }

    /// Solves `w = q + W_AA z` for the contacts listed in `active` (the block is copied
    /// from the full `W`), writing `z` into `z[..active.len()]`; returns the pivots.
    fn solve(
        &mut self,
        w_full: &Mat<f64>,
        active: &[usize],
        q: &[f64],
        z: &mut [f64],
    ) -> Result<usize, LemkeError> {
        let a = active.len();
        for (jj, &j) in active.iter().enumerate() {
            for (ii, &i) in active.iter().enumerate() {
                self.block[(ii, jj)] = w_full[(i, j)];
            }
        }
        let report = self.lemke[a].solve(
            self.block.as_ref().submatrix(0, 0, a, a),
            &q[..a],
            &self.options,
        )?;
        if report.termination != LemkeTermination::Solved {
            return Err(LemkeError::NotSolved {
                termination: report.termination,
                pivots: report.pivots,
                complementarity_error: report.complementarity_error,
            });
        }
        // Lemke's z >= 0 up to round-off: clamp the (tiny) negative parts so that the
        // reported force has the right sign exactly.
        for (zi, ri) in z.iter_mut().zip(&report.z) {
            *zi = ri.max(0.0);
        }
        Ok(report.pivots)
    }
}

/// A one-step marcher: owns the factorization and every buffer, so that
/// [`TimeMarcher::step`] allocates nothing (except inside Lemke's report on steps with
/// an active contact).
pub struct TimeMarcher<'a> {
    model: &'a StructuralModel,
    scheme: Scheme,
    steps_per_period: usize,
    h: f64,
    /// `cos(2 pi j / steps_per_period)`, `j = 0..=steps_per_period`.
    /// The load at the step times.
    load: SampledLoad,
    /// Step index within the current period (0 at a period start).
    phase: usize,
    /// Periods completed.
    completed_periods: usize,
    lu: FaerSparseLu,
    /// `Y = A^{-1} G^T` (N x m, column-major), `A` = K_eff or M_hat.
    y: Vec<f64>,
    /// `W = G Y` (m x m).
    w: Mat<f64>,
    lcp: ContactLcp,
    massless: Vec<bool>,
    u: Vec<f64>,
    v: Vec<f64>,
    /// Inertial force `M a` (trapezoidal only).
    r: Vec<f64>,
    lambda: Vec<f64>,
    /// Set the velocity of a closed contact's dof to 0 after each trapezoidal step.
    reset_closed_velocity: bool,
    rhs: Vec<f64>,
    tmp: Vec<f64>,
    q: Vec<f64>,
    z: Vec<f64>,
    active: Vec<usize>,
    /// The step's contact and friction problem (Moreau–Jean with friction points).
    coulomb: Option<Box<CoulombStep>>,
    /// Friction forces of the last step (impulse / h), one per friction point.
    friction_force: Vec<f64>,
    /// Forces of the last step (impulse / h) on the 3-D frictional contacts' rows (normal
    /// when unilateral, then the two tangents, per contact).
    frictional_force: Vec<f64>,
    /// `G v_free` of every row, `e g . v_n` and the predicted state of every unilateral row.
    row_free: Vec<f64>,
    restitution: Vec<f64>,
    closed: Vec<bool>,
    counters: MarchCounters,
}

impl<'a> TimeMarcher<'a> {
    /// Validates the options, the model, the forcing frequency `omega` (finite, `> 0`) and
    /// the initial state, factors the iteration matrix and prepares `Y`, `W` and the initial
    /// inertial force. The time starts at 0.
    pub fn new(
        model: &'a StructuralModel,
        omega: f64,
        options: &MarchOptions,
        initial: &MarchState,
    ) -> Result<Self, MarchError> {
        options.validate()?;
        model.validate()?;
        model.refuse_cyclic("time marching")?;
        crate::jenkins::refuse_unexpanded(model)?;
        check_omega(omega)?;
        let n = model.dofs();
        let m = model.contact_count();
        initial.check(n, m)?;
        let scheme = Scheme::resolve(model, options.scheme);
        if scheme == Scheme::Trapezoidal && model.has_friction() {
            return Err(MarchError::InvalidOption(InvalidOption::new(
                "friction marched by the trapezoidal scheme (every row dof massless)",
                (model.friction.len() + model.frictional_contacts.len()) as f64,
                "none: Coulomb's law acts on velocities, the trapezoidal scheme imposes \
                          positions; march with MoreauJean",
            )));
        }
        let rows = model.row_count();
        let massless: Vec<bool> = (0..n)
            .map(|j| column_max_abs(&model.mass, j) == 0.0)
            .collect();
        let spp = options.steps_per_period;
        let h = 2.0 * PI / omega / spp as f64;
        // a K + b D + c M, summed in the order K, D, M.
        let (a, b, c) = match scheme {
            Scheme::Trapezoidal => {
                if let Some(dof) = massive_contact_dof(model, &massless) {
                    return Err(MarchError::MassiveContactDof {
                        dof,
                        mass: column_max_abs(&model.mass, dof),
                    });
                }
                (1.0, 2.0 / h, 4.0 / (h * h))
            }
            Scheme::MoreauJean { theta, .. } => (h * h * theta * theta, h * theta, 1.0),
        };
        let mut sources = vec![(&model.stiffness, a)];
        sources.extend(model.damping.as_ref().map(|d| (d, b)));
        sources.push((&model.mass, c));
        let (matrices, coefficients): (Vec<&SparseMatrix>, Vec<f64>) = sources.into_iter().unzip();
        let matrix = UnionPattern::linear_combination(n, &matrices, &coefficients);
        let failed = |source| MarchError::Factorization {
            matrix: scheme.matrix(),
            source,
        };
        let mut lu = FaerSparseLu::new();
        lu.factor(&matrix).map_err(failed)?;
        // Y = A^{-1} G^T, column k for row k (contacts, then friction points); W = G Y.
        let mut y = vec![0.0; n * rows];
        let mut w = Mat::zeros(rows, rows);
        for (k, row_k) in model.rows().enumerate() {
            let col = &mut y[k * n..(k + 1) * n];
            row_k.add_transpose_at(1.0, col, 0);
            lu.solve_in_place(col).map_err(failed)?;
            for (i, row_i) in model.rows().enumerate() {
                w[(i, k)] = row_i.dot(col);
            }
        }
        let coulomb = model
            .has_friction()
            .then(|| Box::new(CoulombStep::new(model, w.clone(), h)));
        let mut marcher = Self {
            model,
            scheme,
            steps_per_period: spp,
            h,
            load: SampledLoad::new(&model.load, spp),
            phase: 0,
            completed_periods: 0,
            lu,
            y,
            w,
            lcp: ContactLcp::new(m),
            massless,
            u: initial.displacement.clone(),
            v: initial.velocity.clone(),
            r: vec![0.0; n],
            reset_closed_velocity: false,
            lambda: initial.contact_force.clone(),
            rhs: vec![0.0; n],
            tmp: vec![0.0; n],
            q: vec![0.0; m],
            z: vec![0.0; m],
            active: Vec::with_capacity(m),
            coulomb,
            friction_force: vec![0.0; model.friction_count()],
            frictional_force: vec![0.0; rows - m - model.friction_count()],
            row_free: vec![0.0; rows],
            restitution: vec![0.0; rows],
            closed: vec![false; rows],
            counters: MarchCounters {
                factorizations: 1,
                linear_solves: rows as u64 + 1,
                ..MarchCounters::default()
            },
        };
        if scheme == Scheme::Trapezoidal {
            marcher.equilibrium_inertia(0);
        }
        Ok(marcher)
    }

    /// `r = f(t_j) + G^T lambda - D v - K u`, zero on massless rows.
    fn equilibrium_inertia(&mut self, j: usize) {
        let model = self.model;
        self.load.write(j, (1.0, 0.0), 1.0, &mut self.r);
        for (ct, l) in model.contacts.iter().zip(&self.lambda) {
            ct.row.add_transpose_at(*l, &mut self.r, 0);
        }
        if let Some(d) = &model.damping {
            sparse_mul_add(d.as_ref(), -1.0, &self.v, &mut self.r);
        }
        sparse_mul_add(model.stiffness.as_ref(), -1.0, &self.u, &mut self.r);
        for (ri, &ml) in self.r.iter_mut().zip(&self.massless) {
            if ml {
                *ri = 0.0;
            }
        }
    }

    /// The scheme in use (never `Auto`).
    pub fn scheme(&self) -> MarchScheme {
        self.scheme.public()
    }

    /// The time step `h = T / steps_per_period`.
    pub fn step_size(&self) -> f64 {
        self.h
    }

    /// Current time, measured from the start of the march.
    pub fn time(&self) -> f64 {
        (self.completed_periods * self.steps_per_period + self.phase) as f64 * self.h
    }

    /// Step index within the current period (0 at a period start).
    pub fn phase(&self) -> usize {
        self.phase
    }

    /// Current displacements `u_n`.
    pub fn displacement(&self) -> &[f64] {
        &self.u
    }

    /// Current velocities `v_n`.
    pub fn velocity(&self) -> &[f64] {
        &self.v
    }

    /// Contact forces of the last step (`lambda <= 0`; impulse / h for Moreau–Jean).
    pub fn contact_force(&self) -> &[f64] {
        &self.lambda
    }

    /// Friction forces of the last step (impulse / h), one per friction point.
    pub fn friction_force(&self) -> &[f64] {
        &self.friction_force
    }

    /// Forces of the last step (impulse / h) on the 3-D frictional contacts' rows: per
    /// contact its normal force (when unilateral; `<= 0`) and its two tangential forces.
    pub fn frictional_force(&self) -> &[f64] {
        &self.frictional_force
    }

    /// Writes the slip velocities of the 3-D frictional contacts, `g_a . v` minus the
    /// obstacle's sliding velocity, two per contact, into `out`.
    pub fn frictional_slip_velocities(&self, out: &mut [f64]) {
        let tangents = (self.model.frictional_contacts.iter())
            .flat_map(|p| p.tangents.iter().zip(p.sliding_velocity));
        for (o, (row, sliding)) in out.iter_mut().zip(tangents) {
            *o = row.dot(&self.v) - sliding;
        }
    }

    /// Work so far.
    pub fn counters(&self) -> MarchCounters {
        self.counters
    }

    /// A copy of the current state.
    pub fn state(&self) -> MarchState {
        MarchState {
            displacement: self.u.clone(),
            velocity: self.v.clone(),
            contact_force: self.lambda.clone(),
        }
    }

    /// Advances one step.
    pub fn step(&mut self) -> Result<(), MarchError> {
        let j = self.phase;
        match self.scheme {
            Scheme::Trapezoidal => self.step_trapezoidal(j)?,
            Scheme::MoreauJean { theta, restitution } => {
                self.step_moreau_jean(j, theta, restitution)?
            }
        }
        self.counters.steps += 1;
        if self.u.iter().chain(&self.v).any(|x| !x.is_finite()) {
            return Err(MarchError::NonFinite {
                period: self.completed_periods + 1,
                step: j + 1,
            });
        }
        self.phase += 1;
        if self.phase == self.steps_per_period {
            self.phase = 0;
            self.completed_periods += 1;
        }
        Ok(())
    }

    fn lcp_error(&self, j: usize, source: LemkeError) -> MarchError {
        MarchError::ContactSolve {
            period: self.completed_periods + 1,
            step: j + 1,
            source,
        }
    }

    /// Solves the LCP `w = q + W_AA z` on the active contacts (none: `lambda = 0`), applies
    /// `rhs -= Y_A z` and sets `lambda_k = -z_k * force_scale`.
    fn solve_contacts(&mut self, j: usize, force_scale: f64) -> Result<(), MarchError> {
        self.lambda.fill(0.0);
        if self.active.is_empty() {
            return Ok(());
        }
        let n = self.u.len();
        let pivots = self
            .lcp
            .solve(&self.w, &self.active, &self.q, &mut self.z)
            .map_err(|err| self.lcp_error(j, err))?;
        self.counters.contact_solves += 1;
        self.counters.lemke_pivots += pivots as u64;
        let mut any = false;
        for (a, &k) in self.active.iter().enumerate() {
            let zk = self.z[a];
            if zk > 0.0 {
                any = true;
                self.lambda[k] = -zk * force_scale;
                let col = &self.y[k * n..(k + 1) * n];
                for (xi, yi) in self.rhs.iter_mut().zip(col) {
                    *xi -= yi * zk;
                }
            }
        }
        if any {
            self.counters.active_steps += 1;
        }
        Ok(())
    }

    /// `rhs <- A^{-1} rhs` with the iteration matrix (counted).
    fn solve_rhs(&mut self) -> Result<(), MarchError> {
        self.lu
            .solve_in_place(&mut self.rhs)
            .map_err(|source| MarchError::Factorization {
                matrix: self.scheme.matrix(),
                source,
            })?;
        self.counters.linear_solves += 1;
        Ok(())
    }

    fn step_trapezoidal(&mut self, j: usize) -> Result<(), MarchError> {
        let model = self.model;
        let n = self.u.len();
        let h = self.h;
        // rhs = f_{n+1} + r_n + M (4/h^2 u + 4/h v) + D (2/h u + v)
        self.load.write(j, (0.0, 1.0), 1.0, &mut self.rhs);
        for i in 0..n {
            self.rhs[i] += self.r[i];
            self.tmp[i] = 4.0 / (h * h) * self.u[i] + 4.0 / h * self.v[i];
        }
        sparse_mul_add(model.mass.as_ref(), 1.0, &self.tmp, &mut self.rhs);
        if let Some(d) = &model.damping {
            for i in 0..n {
                self.tmp[i] = 2.0 / h * self.u[i] + self.v[i];
            }
            sparse_mul_add(d.as_ref(), 1.0, &self.tmp, &mut self.rhs);
        }
        self.solve_rhs()?;
        // rhs = u_free. Contact LCP on all contacts (when one is closed): q = g - G u_free.
        self.active.clear();
        let mut closed = false;
        for (k, ct) in model.contacts.iter().enumerate() {
            self.q[k] = ct.gap - ct.row.dot(&self.rhs);
            closed |= self.q[k] < 0.0;
        }
        if closed {
            self.active.extend(0..model.contacts.len());
        }
        self.solve_contacts(j, 1.0)?;
        // v_{n+1} = 2/h (u_{n+1} - u_n) - v_n; then u <- u_{n+1}.
        for i in 0..n {
            self.v[i] = 2.0 / h * (self.rhs[i] - self.u[i]) - self.v[i];
        }
        // Optionally (stability analysis), a closed contact holds its massless dof at the gap
        // with velocity 0 (module `tangent`).
        if self.reset_closed_velocity {
            for (ct, l) in model.contacts.iter().zip(&self.lambda) {
                if *l < 0.0 {
                    remove_row_component(&ct.row, &mut self.v, |v, i| &mut v[i]);
                }
            }
        }
        std::mem::swap(&mut self.u, &mut self.rhs);
        self.equilibrium_inertia(j + 1);
        Ok(())
    }

    fn step_moreau_jean(&mut self, j: usize, theta: f64, e: f64) -> Result<(), MarchError> {
        let model = self.model;
        let n = self.u.len();
        let h = self.h;
        // rhs = M v - h D (1 - theta) v - h K (u + h theta (1 - theta) v) + h f_theta
        self.load.write(j, (1.0 - theta, theta), h, &mut self.rhs);
        sparse_mul_add(model.mass.as_ref(), 1.0, &self.v, &mut self.rhs);
        if let Some(d) = &model.damping {
            sparse_mul_add(d.as_ref(), -h * (1.0 - theta), &self.v, &mut self.rhs);
        }
        for i in 0..n {
            self.tmp[i] = self.u[i] + h * theta * (1.0 - theta) * self.v[i];
        }
        sparse_mul_add(model.stiffness.as_ref(), -h, &self.tmp, &mut self.rhs);
        self.solve_rhs()?;
        if self.coulomb.is_some() {
            self.solve_contacts_with_friction(j, (theta, e))?;
        } else {
            self.solve_impacts(j, e)?;
        }
        // u_{n+1} = u_n + h (theta v_{n+1} + (1 - theta) v_n)
        for i in 0..n {
            self.u[i] += h * (theta * self.rhs[i] + (1.0 - theta) * self.v[i]);
        }
        std::mem::swap(&mut self.v, &mut self.rhs);
        Ok(())
    }

    /// The frictionless Moreau–Jean contact step on `rhs = v_free`: the active set from the
    /// predicted gap `g - G (u + h/2 v)`, the impact LCP by Lemke.
    fn solve_impacts(&mut self, j: usize, e: f64) -> Result<(), MarchError> {
        let model = self.model;
        let h = self.h;
        self.active.clear();
        for (k, ct) in model.contacts.iter().enumerate() {
            let (gu, gv) = (ct.row.dot(&self.u), ct.row.dot(&self.v));
            if ct.gap - (gu + 0.5 * h * gv) <= 0.0 {
                self.q[self.active.len()] = -(ct.row.dot(&self.rhs) + e * gv);
                self.active.push(k);
            }
        }
        self.solve_contacts(j, 1.0 / h)
    }

    /// The Moreau–Jean contact and friction step on `rhs = v_free` (module
    /// [`super::friction`]): unilateral rows closed by the predicted gap, the impulses by the
    /// core's semismooth Newton, `rhs += Y r`. A moving obstacle enters as the relative
    /// velocities: its gap rate `gap'(t)` off a 3-D contact's normal row, its sliding
    /// velocity off the tangent rows. A 3-D contact's normal row on massless dofs only
    /// carries no inertia, so it takes Signorini's law on the positions at `t_{n+1}`
    /// instead of an impact law: `g_n . u_{n+1} <= gap(t_{n+1})` with
    /// `u_{n+1} = u_n + h (theta v_{n+1} + (1 - theta) v_n)`, i.e. the row velocity
    /// `g_n . v_{n+1}` at most `(gap(t_{n+1}) - g_n . u_n - h (1 - theta) g_n . v_n) /
    /// (h theta)`, always in the step's problem (no predicted active set, which a massless
    /// dof resting on the gap would leave by round-off and then jump past the obstacle).
    fn solve_contacts_with_friction(
        &mut self,
        j: usize,
        (theta, e): (f64, f64),
    ) -> Result<(), MarchError> {
        let model = self.model;
        let (n, h) = (self.u.len(), self.h);
        for (k, row) in model.rows().enumerate() {
            self.row_free[k] = row.dot(&self.rhs);
        }
        let unilateral = model.contacts.iter().map(|ct| (&ct.row, ct.gap, 0.0, 0.0));
        let (t, omega) = (j as f64 * h, self.omega());
        let mut row = model.contact_count() + model.friction_count();
        let mut obstacles = Vec::new();
        for point in &model.frictional_contacts {
            if let Some(normal) = point.normal_row() {
                let (gap, _) = point.gap_at(omega, t + 0.5 * h);
                let (_, rate_before) = point.gap_at(omega, t);
                let (gap_after, rate_after) = point.gap_at(omega, t + h);
                if normal.dofs().iter().all(|d| self.massless[*d]) {
                    let (gu, gv) = (normal.dot(&self.u), normal.dot(&self.v));
                    let reach = gap_after - gu - h * (1.0 - theta) * gv;
                    self.row_free[row] -= reach / (h * theta);
                    (self.closed[row], self.restitution[row]) = (true, 0.0);
                } else {
                    self.row_free[row] -= rate_after;
                    obstacles.push((row, (normal, gap, rate_before, rate_after)));
                }
                row += 1;
            }
            for a in 0..2 {
                self.row_free[row + a] -= point.sliding_velocity[a];
            }
            row += 2;
        }
        let rows = (0..model.contact_count()).zip(unilateral);
        for (k, (normal, gap, rate_before, _)) in rows.chain(obstacles) {
            let (gu, gv) = (normal.dot(&self.u), normal.dot(&self.v));
            self.closed[k] = gap - (gu + 0.5 * h * gv) <= 0.0;
            self.restitution[k] = e * (gv - rate_before);
        }
        let coulomb = self.coulomb.as_mut().expect("friction present");
        let solved = coulomb.solve(&self.row_free, &self.restitution, &self.closed);
        solved.map_err(|unsolved| MarchError::FrictionSolve {
            period: self.completed_periods + 1,
            step: j + 1,
            residual: unsolved.residual,
            tolerance: unsolved.tolerance,
        })?;
        self.counters.contact_solves += 1;
        let (m, nf) = (model.contact_count(), model.friction_count());
        let mut any = false;
        for (k, r) in coulomb.impulses().enumerate() {
            if k < m {
                self.lambda[k] = r / h;
            } else if k < m + nf {
                self.friction_force[k - m] = r / h;
            } else {
                self.frictional_force[k - m - nf] = r / h;
            }
            if r != 0.0 {
                any = true;
                let col = &self.y[k * n..(k + 1) * n];
                for (xi, yi) in self.rhs.iter_mut().zip(col) {
                    *xi += yi * r;
                }
            }
        }
        if any {
            self.counters.active_steps += 1;
        }
        Ok(())
    }

    /// The forcing's angular frequency `2 pi / (steps_per_period h)`.
    fn omega(&self) -> f64 {
        2.0 * PI / (self.steps_per_period as f64 * self.h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lemke_step_lcp_agrees_with_the_closed_form_for_one_contact() {
        // m = 1: w = q + W z, z >= 0, w >= 0, w z = 0 has the unique solution
        // z = max(0, -q / W) for W > 0.
        let mut lcp = ContactLcp::new(1);
        let mut z = [0.0];
        for &(wv, q) in &[
            (0.3, -0.7),
            (2.5, 1e-3),
            (1e-4, -3.0),
            (7.0, 0.0),
            (1.0, -1e-14),
        ] {
            let w = Mat::from_fn(1, 1, |_, _| wv);
            lcp.solve(&w, &[0], &[q], &mut z).unwrap();
            let exact = f64::max(0.0, -q / wv);
            assert!(
                (z[0] - exact).abs() <= 1e-14 * exact.max(1.0),
                "W={wv} q={q}: {} vs {exact}",
                z[0]
            );
        }
    }

    #[test]
    fn lemke_step_lcp_on_an_active_subset_matches_enumeration() {
        // W symmetric positive definite 3x3, active set {0, 2}: compare with the solution
        // found by enumerating the 4 complementary index sets of the 2x2 block.
        let w = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 + i as f64 } else { 0.5 });
        let active = [0usize, 2];
        let q = [-1.0, 0.4];
        let mut lcp = ContactLcp::new(3);
        let mut z = [0.0; 3];
        lcp.solve(&w, &active, &q, &mut z).unwrap();
        let (a, b, d) = (w[(0, 0)], w[(0, 2)], w[(2, 2)]);
        let mut best = None;
        for mask in 0..4u32 {
            let mut zz = [0.0, 0.0];
            match mask {
                1 => zz[0] = -q[0] / a,
                2 => zz[1] = -q[1] / d,
                3 => {
                    let det = a * d - b * b;
                    zz[0] = (-q[0] * d + q[1] * b) / det;
                    zz[1] = (-q[1] * a + q[0] * b) / det;
                }
                _ => {}
            }
            let ww = [q[0] + a * zz[0] + b * zz[1], q[1] + b * zz[0] + d * zz[1]];
            if zz.iter().chain(&ww).all(|v| *v >= -1e-15) {
                best = Some(zz);
            }
        }
        let best = best.unwrap();
        assert!((z[0] - best[0]).abs() < 1e-14 && (z[1] - best[1]).abs() < 1e-14);
    }
}
