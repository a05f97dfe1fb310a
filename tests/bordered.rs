//! The multi-right-hand-side solve and the bordered solver `[[J, B], [C^T, D]]` against a
//! dense LU of the assembled matrix, their typed errors and work counters, and the
//! continuation corrector's use of them (one inner factorization per corrector iteration,
//! counted by the inner solver itself).

mod common;

use common::branches::{between, duffing, s_curve};
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use semismooth::continuation::Continuation;
use semismooth::linalg::{
    BorderedError, BorderedSolver, FaerDenseLu, FaerSparseLu, LinearSolveError, NalgebraLu,
};
use semismooth::{Factorize, LinearSolve};

/// Sizes around faer's block boundaries.
const SIZES: [usize; 6] = [1, 2, 3, 17, 128, 257];

/// Seeded entries in [-1, 1] plus `n` on the diagonal: strictly diagonally dominant, with
/// a condition number below about 2n whatever the draw.
fn well_conditioned(n: usize, rng: &mut ChaCha8Rng) -> Mat<f64> {
    let mut a = Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    for i in 0..n {
        a[(i, i)] += n as f64;
    }
    a
}

fn random_vec(len: usize, rng: &mut ChaCha8Rng) -> Vec<f64> {
    (0..len).map(|_| rng.random_range(-1.0..1.0)).collect()
}

fn to_sparse(a: &Mat<f64>) -> SparseColMat<usize, f64> {
    let mut t = Vec::new();
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            t.push(Triplet::new(i, j, a[(i, j)]));
        }
    }
    SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &t).unwrap()
}

fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
    let num: f64 = x.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum();
    let den: f64 = y.iter().map(|b| b * b).sum();
    (num / den).sqrt()
}

/// A random bordered system: `J` (n x n), `B`, `C` (n x k), `D` (k x k, plus 2n on the
/// diagonal so that the Schur complement stays away from singular) and the right-hand side.
struct System {
    j: Mat<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
    rhs: Vec<f64>,
}

impl System {
    fn random(n: usize, k: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let j = well_conditioned(n, &mut rng);
        let (b, c) = (random_vec(n * k, &mut rng), random_vec(n * k, &mut rng));
        let mut d = random_vec(k * k, &mut rng);
        for i in 0..k {
            d[i + i * k] += 2.0 * n as f64;
        }
        let rhs = random_vec(n + k, &mut rng);
        Self { j, b, c, d, rhs }
    }

    /// The solution by faer's LU of the assembled `(n + k) x (n + k)` matrix.
    fn dense_solution(&self, n: usize, k: usize) -> Vec<f64> {
        let m = Mat::from_fn(n + k, n + k, |r, s| match (r < n, s < n) {
            (true, true) => self.j[(r, s)],
            (true, false) => self.b[r + (s - n) * n],
            (false, true) => self.c[s + (r - n) * n],
            (false, false) => self.d[(r - n) + (s - n) * k],
        });
        let mut x = Mat::from_fn(n + k, 1, |r, _| self.rhs[r]);
        PartialPivLu::new(m.as_ref()).solve_in_place(x.as_mut());
        (0..n + k).map(|r| x[(r, 0)]).collect()
    }

    /// The solution by the bordered solver with `inner` factoring `jac`.
    fn bordered_solution<J, S: Factorize<J>>(&self, inner: &mut S, jac: &J, k: usize) -> Vec<f64> {
        let n = self.j.nrows();
        let mut bordered = BorderedSolver::new(n, k);
        bordered
            .factor(inner, jac, &self.b, &self.c, &self.d)
            .unwrap();
        let (mut f, mut g) = (self.rhs[..n].to_vec(), self.rhs[n..].to_vec());
        bordered.solve(inner, &mut f, &mut g).unwrap();
        f.extend_from_slice(&g);
        f
    }
}

/// Block elimination and the dense LU of the assembled matrix both solve a system whose
/// condition number is a few n (diagonally dominant J, Schur complement near 2n I): each
/// has a forward error of about n eps cond ~ 257 * 2.2e-16 * 514 ~ 3e-11 at worst, so
/// they agree to 1e-10 (measured: below 1e-14 at every size).
#[test]
fn bordered_solve_matches_dense_lu_of_the_assembled_matrix_for_dense_and_sparse_inner_solvers() {
    let mut worst = 0.0_f64;
    for (seed, &n) in SIZES.iter().enumerate() {
        for k in 1..=3 {
            let system = System::random(n, k, (10 * seed + k) as u64);
            let reference = system.dense_solution(n, k);
            let dense = system.bordered_solution(&mut FaerDenseLu::new(), &system.j, k);
            let sparse_j = to_sparse(&system.j);
            let sparse = system.bordered_solution(&mut FaerSparseLu::new(), &sparse_j, k);
            for x in [&dense, &sparse] {
                let e = rel_diff(x, &reference);
                worst = worst.max(e);
                assert!(e < 1e-10, "n = {n}, k = {k}: relative difference {e:e}");
            }
        }
    }
    println!("worst relative difference from the assembled LU: {worst:e}");
}

/// The blocked dense and sparse solves of k columns give the solution of each column by
/// nalgebra's LU (an independent implementation solving one column at a time) to the
/// rounding of two backward-stable solves, 1e-12 relative (cond < 2n, n <= 257).
#[test]
fn blocked_multi_column_solves_match_column_by_column_solves_of_another_lu() {
    for (seed, &n) in SIZES.iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(100 + seed as u64);
        let a = well_conditioned(n, &mut rng);
        let k = 3;
        let rhs = random_vec(n * k, &mut rng);
        let mut reference = rhs.clone();
        let mut nalgebra = NalgebraLu::new();
        nalgebra.factor(&a).unwrap();
        nalgebra.solve_columns_in_place(&mut reference, k).unwrap();
        let mut one = rhs[..n].to_vec();
        nalgebra.solve_in_place(&mut one).unwrap();
        assert_eq!(one, reference[..n], "the default solves column by column");
        let mut dense = FaerDenseLu::new();
        dense.factor(&a).unwrap();
        let mut sparse = FaerSparseLu::new();
        sparse.factor(&to_sparse(&a)).unwrap();
        for solver in [&mut dense as &mut dyn LinearSolve, &mut sparse] {
            let mut x = rhs.clone();
            solver.solve_columns_in_place(&mut x, k).unwrap();
            let e = rel_diff(&x, &reference);
            assert!(e < 1e-12, "n = {n}: relative difference {e:e}");
        }
    }
}

/// `J = I`, `B = C = e_0`, `D = 1`: the Schur complement `1 - 1` is exactly zero although
/// `J` is regular; with k = 2 (`B = C = [e_0, e_1]`, `D = I`) the first pivot is zero.
#[test]
fn exactly_singular_border_is_a_typed_error_with_its_pivot_and_scale() {
    let eye = Mat::<f64>::identity(3, 3);
    let mut lu = FaerDenseLu::new();
    let mut one = BorderedSolver::new(3, 1);
    let e0 = [1.0, 0.0, 0.0];
    let error = one.factor(&mut lu, &eye, &e0, &e0, &[1.0]).unwrap_err();
    // Scale |D| + |C| |X| = 1 + 1.
    assert_eq!(
        error,
        BorderedError::SingularBorder {
            index: 0,
            pivot: 0.0,
            scale: 2.0
        }
    );
    // No factorization is left to solve with.
    let (mut f, mut g) = ([1.0; 3], [1.0]);
    assert_eq!(
        one.solve(&mut lu, &mut f, &mut g),
        Err(BorderedError::Solve(LinearSolveError::NotFactored))
    );
    let mut two = BorderedSolver::new(3, 2);
    let e01 = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let error = two.factor(&mut lu, &eye, &e01, &e01, &[1.0, 0.0, 0.0, 1.0]);
    assert!(matches!(
        error,
        Err(BorderedError::SingularBorder { index: 0, pivot, .. }) if pivot == 0.0
    ));
}

/// A border of the wrong size, and a singular inner matrix, are typed errors.
#[test]
fn wrong_sizes_and_a_singular_inner_matrix_are_typed_errors() {
    let mut lu = FaerDenseLu::new();
    let mut bordered = BorderedSolver::new(2, 1);
    let eye = Mat::<f64>::identity(2, 2);
    let error = bordered.factor(&mut lu, &eye, &[1.0], &[1.0, 0.0], &[1.0]);
    assert_eq!(
        error,
        Err(BorderedError::DimensionMismatch {
            what: "B",
            expected: 2,
            found: 1
        })
    );
    let zero = Mat::<f64>::zeros(2, 2);
    let error = bordered.factor(&mut lu, &zero, &[1.0, 0.0], &[1.0, 0.0], &[1.0]);
    assert!(matches!(
        error,
        Err(BorderedError::Factorization(
            LinearSolveError::Singular { .. }
        ))
    ));
    // Three numbers are not two columns of a 2 x 2 system.
    lu.factor(&eye).unwrap();
    let mut odd = [0.0; 3];
    assert!(matches!(
        lu.solve_columns_in_place(&mut odd, 2),
        Err(LinearSolveError::DimensionMismatch { .. })
    ));
}

/// An inner solver that counts its own factorizations and right-hand sides.
#[derive(Default)]
struct Counting {
    lu: FaerDenseLu,
    factorizations: u64,
    solves: u64,
}

impl LinearSolve for Counting {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        self.solves += 1;
        self.lu.solve_in_place(rhs)
    }
}

impl Factorize<Mat<f64>> for Counting {
    fn factor(&mut self, jac: &Mat<f64>) -> Result<(), LinearSolveError> {
        self.factorizations += 1;
        self.lu.factor(jac)
    }
}

/// One factorization of `J` and `k + 1` solves per bordered solve; a new border with the
/// same `J` costs `k` solves and no factorization (counted by the inner solver).
#[test]
fn one_inner_factorization_and_k_plus_one_solves_counted_by_the_inner_solver() {
    let (n, k) = (17, 3);
    let system = System::random(n, k, 7);
    let mut inner = Counting::default();
    let mut bordered = BorderedSolver::new(n, k);
    bordered
        .factor(&mut inner, &system.j, &system.b, &system.c, &system.d)
        .unwrap();
    let (mut f, mut g) = (system.rhs[..n].to_vec(), system.rhs[n..].to_vec());
    bordered.solve(&mut inner, &mut f, &mut g).unwrap();
    assert_eq!((inner.factorizations, inner.solves), (1, k as u64 + 1));
    let mut c2 = system.c.clone();
    c2.iter_mut().for_each(|v| *v *= 0.5);
    bordered
        .factor_border(&mut inner, &system.b, &c2, &system.d)
        .unwrap();
    let (mut f, mut g) = (system.rhs[..n].to_vec(), system.rhs[n..].to_vec());
    bordered.solve(&mut inner, &mut f, &mut g).unwrap();
    assert_eq!((inner.factorizations, inner.solves), (1, 2 * k as u64 + 2));
    let counted = bordered.counters();
    assert_eq!(
        (counted.factorizations, counted.solves),
        (1, 2 * k as u64 + 2)
    );
    // The second border's solution against the assembled matrix (as above, 1e-10).
    let other = System { c: c2, ..system };
    f.extend_from_slice(&g);
    assert!(rel_diff(&f, &other.dense_solution(n, k)) < 1e-10);
}

/// The continuation corrector factors the inner solver once per corrector iteration and
/// solves twice (`J a = F_p`, `J b = F`), on the S-curve (two folds) and Duffing's first
/// harmonic (two folds, n = 2): counted by the solver, not by the driver.
#[test]
fn continuation_factors_the_inner_solver_once_per_corrector_iteration() {
    for (mut problem, x0, p0, range) in [
        (s_curve(), vec![-1.3], -1.0, between(-1.0, 1.0)),
        (duffing(), vec![0.13, 0.0], 0.5, between(0.5, 2.0)),
    ] {
        let mut inner = Counting::default();
        let branch = Continuation::new(&mut problem, &mut inner, &x0, p0, range)
            .unwrap()
            .run();
        let c = branch.counters;
        println!(
            "{} points, {} corrector iterations, {} inner factorizations, {} solves",
            branch.points.len(),
            c.corrector_iterations,
            inner.factorizations,
            inner.solves
        );
        assert!(branch.points.len() > 10 && branch.fold_parameters().len() == 2);
        assert_eq!(inner.factorizations, c.corrector_iterations);
        assert_eq!(inner.factorizations, c.work.factorizations);
        assert_eq!(inner.solves, 2 * c.corrector_iterations);
        assert_eq!(c.dense_bordered_factorizations, 0);
    }
}
