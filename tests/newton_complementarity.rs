//! Semismooth Newton on complementarity problems with known answers: a P-matrix LCP written
//! with the min, max and Fischer-Burmeister functions against brute-force enumeration, a
//! sparse obstacle problem against the dense solve, and repeated solves that allocate
//! nothing per iteration.

mod common;

use common::allocations;
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use semismooth::complementarity::{fischer_burmeister, max_form, min_function, PhiValue};
use semismooth::linalg::{FaerDenseLu, FaerSparseLu, NalgebraLu};
use semismooth::newton::{
    solve, Globalization, NewtonError, NewtonOptions, NewtonReport, NewtonSolver, Tolerances,
    EXACT_RESIDUAL,
};
use semismooth::polyalgorithm::{self, Polyalgorithm, PolyalgorithmOptions};
use semismooth::{EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, Residual};

/// An LCP `w = A z + q, z, w >= 0, z . w = 0` with a P-matrix, written with a
/// complementarity function `phi(z_i, w_i) = 0`.
#[derive(Clone, Copy, Debug)]
enum Phi {
    Min,
    /// The paper's max form in the sign convention `-z, -w <= 0`, with constant c.
    Max(f64),
    FischerBurmeister,
}

struct Lcp {
    a: Mat<f64>,
    q: Vec<f64>,
    phi: Phi,
    w: Vec<f64>,
}
impl Lcp {
    fn eval(&mut self, z: &[f64]) {
        let n = self.q.len();
        for i in 0..n {
            self.w[i] = self.q[i] + (0..n).map(|j| self.a[(i, j)] * z[j]).sum::<f64>();
        }
    }
    fn phi(&self, z: f64, w: f64) -> PhiValue {
        match self.phi {
            Phi::Min => min_function(z, w),
            Phi::Max(c) => {
                // phi(-z, -w): d/dz = -da, d/dw = -db.
                let v = max_form(-z, -w, c);
                PhiValue {
                    value: v.value,
                    da: -v.da,
                    db: -v.db,
                }
            }
            Phi::FischerBurmeister => fischer_burmeister(z, w),
        }
    }
}
impl Residual for Lcp {
    fn dim(&self) -> usize {
        self.q.len()
    }
    fn residual(&mut self, z: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.eval(z);
        for i in 0..self.dim() {
            out[i] = self.phi(z[i], self.w[i]).value;
        }
        Ok(())
    }
}
impl GeneralizedJacobian for Lcp {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.dim(), self.dim())
    }
    fn jacobian(&mut self, z: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        self.eval(z);
        let n = self.dim();
        for i in 0..n {
            let g = self.phi(z[i], self.w[i]);
            for j in 0..n {
                jac[(i, j)] = g.db * self.a[(i, j)] + if i == j { g.da } else { 0.0 };
            }
        }
        Ok(())
    }
}

/// Brute force: for each of the 2^n index sets S, solve A_SS z_S = -q_S with z = 0
/// off S, keep the z with z >= 0 and w = A z + q >= 0 (unique for a P-matrix).
fn lcp_by_enumeration(a: &Mat<f64>, q: &[f64]) -> Vec<f64> {
    let n = q.len();
    let mut found = Vec::new();
    for mask in 0u32..(1 << n) {
        let s: Vec<usize> = (0..n).filter(|i| mask & (1 << i) != 0).collect();
        let sub = Mat::from_fn(s.len(), s.len(), |i, j| a[(s[i], s[j])]);
        let mut rhs: Vec<f64> = s.iter().map(|&i| -q[i]).collect();
        let mut lu = NalgebraLu::new();
        if lu.factor(&sub).is_err() || lu.solve_in_place(&mut rhs).is_err() {
            continue;
        }
        let mut z = vec![0.0; n];
        for (k, &i) in s.iter().enumerate() {
            z[i] = rhs[k];
        }
        let w: Vec<f64> = (0..n)
            .map(|i| q[i] + (0..n).map(|j| a[(i, j)] * z[j]).sum::<f64>())
            .collect();
        if z.iter().all(|&v| v >= -1e-12) && w.iter().all(|&v| v >= -1e-12) {
            found.push(z);
        }
    }
    assert_eq!(found.len(), 1, "a P-matrix LCP has exactly one solution");
    found.pop().unwrap()
}

/// A seeded 8x8 LCP with a strictly diagonally dominant, positive-diagonal (hence P-)
/// matrix, and q built from a chosen strictly complementary pair (z*, w*):
/// q = w* - A z*, with z*_i = 0.5 + i/8 on even i and w*_i = 1 on odd i.
fn strictly_complementary_lcp(phi: Phi) -> (Lcp, Vec<f64>) {
    let n = 8;
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut a = Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    for i in 0..n {
        a[(i, i)] = n as f64 + rng.random_range(0.0..1.0);
    }
    let z_star: Vec<f64> = (0..n)
        .map(|i| {
            if i % 2 == 0 {
                0.5 + i as f64 / 8.0
            } else {
                0.0
            }
        })
        .collect();
    let w_star: Vec<f64> = (0..n).map(|i| if i % 2 == 1 { 1.0 } else { 0.0 }).collect();
    let q: Vec<f64> = (0..n)
        .map(|i| w_star[i] - (0..n).map(|j| a[(i, j)] * z_star[j]).sum::<f64>())
        .collect();
    let lcp = Lcp {
        a,
        q,
        phi,
        w: vec![0.0; n],
    };
    (lcp, z_star)
}

/// Semismooth Newton on the LCP with a strictly complementary solution:
/// - min and max form are piecewise linear, so once the iterate's active pieces are the
///   solution's, one step solves the (linear) system: finite termination. The test
///   measures it: the last step lands at round-off (|F| <= 1e-13, a backward error of a
///   few eps times |A||z| ~ 10) from a residual >= 1e-6, i.e. no quadratic tail, and the
///   estimated order is therefore far above 2.
/// - Fischer–Burmeister is smooth near a strictly complementary solution (away from the
///   kink at (0, 0)), so it converges Q-quadratically: observed order >= 1.8.
///
/// All agree with the brute-force enumeration to 1e-12 (the LCP is well conditioned:
/// cond(A_SS) < 3).
#[test]
fn nonsmooth_lcp_terminates_finitely_with_min_and_max_form_and_quadratically_with_fb() {
    for phi in [
        Phi::Min,
        Phi::Max(1.0),
        Phi::Max(10.0),
        Phi::FischerBurmeister,
    ] {
        let (mut lcp, z_star) = strictly_complementary_lcp(phi);
        let z_enum = lcp_by_enumeration(&lcp.a, &lcp.q);
        for (a, b) in z_enum.iter().zip(&z_star) {
            assert!((a - b).abs() < 1e-12);
        }
        let mut z = vec![1.0; 8];
        let opts = NewtonOptions {
            tolerances: Tolerances::absolute(1e-10),
            globalization: Globalization::non_monotone(),
            ..Default::default()
        };
        let report = solve(&mut lcp, &mut FaerDenseLu::new(), &mut z, &opts).unwrap();
        println!(
            "{phi:?}: iterations {} norms {:?} order {:?}",
            report.iterations, report.residual_norms, report.observed_order
        );
        assert!(report.converged(), "{phi:?}: {:?}", report.termination);
        for (a, b) in z.iter().zip(&z_enum) {
            assert!((a - b).abs() < 1e-12, "{phi:?}: {z:?}");
        }
        let norms = &report.residual_norms;
        let last = norms[norms.len() - 1];
        let before = norms[norms.len() - 2];
        match phi {
            Phi::Min | Phi::Max(_) => {
                let exact = last < EXACT_RESIDUAL;
                if exact {
                    assert_eq!(report.observed_order, None);
                } else {
                    assert!(
                        last <= 1e-13 && before >= 1e-6,
                        "{phi:?}: {before:e} -> {last:e}"
                    );
                    assert!(report.observed_order.is_none_or(|q| q > 2.0));
                }
            }
            Phi::FischerBurmeister => {
                // The run may end exactly at 0 (then `observed_order` is None by
                // definition): measure the order on the last three norms above the
                // round-off floor 1e-13.
                let tail: Vec<f64> = norms.iter().copied().filter(|&r| r > 1e-13).collect();
                let [r1, r2, r3] = tail[tail.len() - 3..] else {
                    unreachable!()
                };
                let q = (r3 / r2).ln() / (r2 / r1).ln();
                assert!(q >= 1.8, "FB order {q}");
                assert!(report.observed_order.is_none_or(|q| q >= 1.8));
            }
        }
    }
}

/// An obstacle problem with a sparse Jacobian: min(u - psi, K u - f) = 0 with K the
/// 1-D Laplacian tridiag(-1, 2, -1) (n = 200) and an obstacle psi that the unloaded
/// solution would cross. Solved with the sparse LU and with the dense LU (the same
/// Jacobian written densely), the solutions agree to 1e-12, and the complementarity
/// conditions hold to 1e-12 (checked directly: u >= psi, K u - f >= 0, product 0).
#[test]
fn sparse_obstacle_problem_matches_dense_solve_and_satisfies_complementarity() {
    /// The obstacle problem, its Jacobian stored as `J` (sparse or dense).
    struct Obstacle<J> {
        n: usize,
        psi: Vec<f64>,
        f: f64,
        storage: std::marker::PhantomData<J>,
    }
    impl<J> Obstacle<J> {
        fn ku(&self, u: &[f64], i: usize) -> f64 {
            let left = if i > 0 { u[i - 1] } else { 0.0 };
            let right = if i + 1 < self.n { u[i + 1] } else { 0.0 };
            2.0 * u[i] - left - right - self.f
        }
        /// Jacobian entry `(i, j)` (zero outside the tridiagonal band).
        fn entry(&self, u: &[f64], i: usize, j: usize) -> f64 {
            let g = min_function(u[i] - self.psi[i], self.ku(u, i));
            let k = match i.abs_diff(j) {
                0 => 2.0,
                1 => -1.0,
                _ => 0.0,
            };
            g.db * k + if i == j { g.da } else { 0.0 }
        }
    }
    /// A Jacobian storage: created for `n` unknowns (the band's pattern for a sparse
    /// matrix, a fixed pattern whose values are overwritten in place), filled entry-wise.
    trait Storage: Sized {
        fn band(n: usize) -> Self;
        fn fill(&mut self, entry: impl Fn(usize, usize) -> f64);
    }
    impl Storage for SparseColMat<usize, f64> {
        fn band(n: usize) -> Self {
            let mut t = Vec::new();
            for j in 0..n {
                for i in j.saturating_sub(1)..(j + 2).min(n) {
                    t.push(Triplet::new(i, j, 0.0));
                }
            }
            SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
        }
        fn fill(&mut self, entry: impl Fn(usize, usize) -> f64) {
            for j in 0..self.ncols() {
                let rows: Vec<usize> = self.row_idx_of_col(j).collect();
                for (v, &i) in self.val_of_col_mut(j).iter_mut().zip(&rows) {
                    *v = entry(i, j);
                }
            }
        }
    }
    impl Storage for Mat<f64> {
        fn band(n: usize) -> Self {
            Mat::zeros(n, n)
        }
        fn fill(&mut self, entry: impl Fn(usize, usize) -> f64) {
            for j in 0..self.ncols() {
                for i in 0..self.nrows() {
                    self[(i, j)] = entry(i, j);
                }
            }
        }
    }
    impl<J> Residual for Obstacle<J> {
        fn dim(&self) -> usize {
            self.n
        }
        fn residual(&mut self, u: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
            for i in 0..self.n {
                out[i] = min_function(u[i] - self.psi[i], self.ku(u, i)).value;
            }
            Ok(())
        }
    }
    impl<J: Storage> GeneralizedJacobian for Obstacle<J> {
        type Jacobian = J;
        fn new_jacobian(&self) -> J {
            J::band(self.n)
        }
        fn jacobian(&mut self, u: &[f64], jac: &mut J) -> Result<(), EvaluationError> {
            jac.fill(|i, j| self.entry(u, i, j));
            Ok(())
        }
    }
    let n = 200;
    fn make<J>(n: usize) -> Obstacle<J> {
        Obstacle {
            n,
            // A tilted obstacle above zero in the middle, below the boundary values.
            psi: (0..n)
                .map(|i| {
                    let t = (i + 1) as f64 / (n + 1) as f64;
                    0.3 - 4.0 * (t - 0.4).powi(2)
                })
                .collect(),
            f: -1e-5,
            storage: std::marker::PhantomData,
        }
    }
    let mut sparse: Obstacle<SparseColMat<usize, f64>> = make(n);
    let mut dense: Obstacle<Mat<f64>> = make(n);
    let opts = PolyalgorithmOptions {
        tolerances: Tolerances::absolute(1e-12),
        ..Default::default()
    };
    let mut us = vec![0.0; n];
    let mut slu = FaerSparseLu::new();
    let rs = polyalgorithm::solve(&mut sparse, &mut slu, &mut us, &opts).unwrap();
    let mut ud = vec![0.0; n];
    let rd = polyalgorithm::solve(&mut dense, &mut FaerDenseLu::new(), &mut ud, &opts).unwrap();
    println!(
        "obstacle: sparse {} it, dense {} it, norms {:?}",
        rs.iterations, rd.iterations, rs.residual_norms
    );
    assert!(rs.converged() && rd.converged());
    assert_eq!(slu.symbolic_analyses(), 1, "one pattern, analysed once");
    let o = &sparse;
    let mut contacts = 0;
    for i in 0..n {
        assert!((us[i] - ud[i]).abs() < 1e-12);
        let gap = us[i] - o.psi[i];
        let w = o.ku(&us, i);
        assert!(
            gap >= -1e-12 && w >= -1e-12 && (gap * w).abs() < 1e-12,
            "node {i}: {gap:e} {w:e}"
        );
        if gap.abs() < 1e-12 {
            contacts += 1;
        }
    }
    assert!(
        contacts > 0 && contacts < n,
        "the obstacle is partly active ({contacts} nodes)"
    );
}

#[global_allocator]
static GLOBAL: common::CountingAllocator = common::CountingAllocator;

/// One warm-up solve (buffers, Jacobian, factor storage), then from each start: the
/// solve converges in >= 3 iterations and makes exactly 5 allocations (the report's
/// residual, step-length and step-norm histories, its list of attempts and the outcome
/// text of the one attempt).
fn warm_then_count_allocations(
    mut solve: impl FnMut(&mut [f64]) -> Result<NewtonReport, NewtonError>,
    x: &mut [f64],
    starts: &[f64],
) {
    assert!(solve(x).unwrap().converged());
    for &start in starts {
        x.fill(start);
        let before = allocations();
        let report = solve(x).unwrap();
        let made = allocations() - before;
        assert!(
            report.converged() && report.iterations >= 3,
            "start {start}"
        );
        assert_eq!(
            made, 5,
            "start {start}: {made} allocations for {} iterations",
            report.iterations
        );
    }
}

/// A reused `NewtonSolver` or `Polyalgorithm` with a reused faer solver (dense or sparse)
/// allocates only the report (three history vectors, the attempt list and its text) per
/// solve, however many iterations it takes: nothing per iteration. Measured with a
/// counting global allocator on this thread.
#[test]
fn repeated_solves_allocate_nothing_per_iteration() {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut newton = NewtonSolver::new(NewtonOptions::default()).unwrap();
    let mut poly = Polyalgorithm::new(PolyalgorithmOptions::default()).unwrap();
    let (mut lcp, _) = strictly_complementary_lcp(Phi::FischerBurmeister);
    let mut lu = FaerDenseLu::new();
    let mut z = vec![1.0; 8];
    let starts = [1.0, 3.0, -2.0];
    warm_then_count_allocations(|z| newton.solve(&mut lcp, &mut lu, z), &mut z, &starts);
    warm_then_count_allocations(|z| poly.solve(&mut lcp, &mut lu, z), &mut z, &starts);

    let n = 200;
    let mut t = Vec::new();
    for i in 0..n {
        t.push(Triplet::new(i, i, 0.0));
        if i + 1 < n {
            t.push(Triplet::new(i + 1, i, 0.0));
            t.push(Triplet::new(i, i + 1, 0.0));
        }
    }
    /// F(u) = K u + u^3 / 10 - 1 with K = tridiag(-1, 3, -1), sparse Jacobian.
    struct Chain(SparseColMat<usize, f64>);
    impl Residual for Chain {
        fn dim(&self) -> usize {
            self.0.nrows()
        }
        fn residual(&mut self, u: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
            let n = u.len();
            for i in 0..n {
                let l = if i > 0 { u[i - 1] } else { 0.0 };
                let r = if i + 1 < n { u[i + 1] } else { 0.0 };
                out[i] = 3.0 * u[i] - l - r + u[i].powi(3) / 10.0 - 1.0;
            }
            Ok(())
        }
    }
    impl GeneralizedJacobian for Chain {
        type Jacobian = SparseColMat<usize, f64>;
        fn new_jacobian(&self) -> Self::Jacobian {
            self.0.clone()
        }
        fn jacobian(&mut self, u: &[f64], jac: &mut Self::Jacobian) -> Result<(), EvaluationError> {
            for (j, uj) in u.iter().enumerate() {
                let (symbolic, values) = jac.parts_mut();
                let rows = symbolic.row_idx_of_col_raw(j);
                let range = symbolic.col_range(j);
                for (v, &i) in values[range].iter_mut().zip(rows) {
                    *v = if i == j { 3.0 + 0.3 * uj * uj } else { -1.0 };
                }
            }
            Ok(())
        }
    }
    let mut chain = Chain(SparseColMat::try_new_from_triplets(n, n, &t).unwrap());
    let mut slu = FaerSparseLu::new();
    let mut u = vec![0.0; n];
    let mut newton_sparse = NewtonSolver::new(NewtonOptions::default()).unwrap();
    let mut poly_sparse = Polyalgorithm::new(PolyalgorithmOptions::default()).unwrap();
    let starts = [0.0, 5.0];
    warm_then_count_allocations(
        |u| newton_sparse.solve(&mut chain, &mut slu, u),
        &mut u,
        &starts,
    );
    warm_then_count_allocations(
        |u| poly_sparse.solve(&mut chain, &mut slu, u),
        &mut u,
        &starts,
    );
    assert_eq!(slu.symbolic_analyses(), 1);
}
