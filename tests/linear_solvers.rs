//! The three `LinearSolve` implementations (faer dense LU, nalgebra LU, faer sparse LU)
//! against each other, against known solutions, and on bad input.

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use semismooth::linalg::{FaerDenseLu, FaerSparseLu, LinearSolveError, NalgebraLu};
use semismooth::{Factorize, LinearSolve};

/// Sizes around faer's block boundaries (its LU tests use the same idea).
const SIZES: [usize; 8] = [1, 2, 3, 17, 64, 128, 255, 257];

/// A seeded random matrix with entries in [-1, 1] plus `n` on the diagonal: strictly
/// diagonally dominant (row sums of |off-diagonal| < n - 1 < n), so its condition number
/// is bounded by about (2n) / 1 independent of the draw.
fn well_conditioned(n: usize, seed: u64) -> Mat<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut a = Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    for i in 0..n {
        a[(i, i)] += n as f64;
    }
    a
}

fn to_sparse(a: &Mat<f64>) -> SparseColMat<usize, f64> {
    let mut t = Vec::new();
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            if a[(i, j)] != 0.0 {
                t.push(Triplet::new(i, j, a[(i, j)]));
            }
        }
    }
    SparseColMat::try_new_from_triplets(a.nrows(), a.ncols(), &t).unwrap()
}

fn to_nalgebra(a: &Mat<f64>) -> nalgebra::DMatrix<f64> {
    nalgebra::DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

fn matvec(a: &Mat<f64>, x: &[f64]) -> Vec<f64> {
    (0..a.nrows())
        .map(|i| (0..a.ncols()).map(|j| a[(i, j)] * x[j]).sum())
        .collect()
}

fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
    let num: f64 = x.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
    let den: f64 = y.iter().map(|b| b * b).sum::<f64>();
    (num / den).sqrt()
}

fn solve_with<J, S: Factorize<J>>(solver: &mut S, jac: &J, b: &[f64]) -> Vec<f64> {
    solver.factor(jac).unwrap();
    let mut x = b.to_vec();
    solver.solve_in_place(&mut x).unwrap();
    x
}

/// With b = A x_true, each solver recovers x_true to relative 1e-10 and the three agree.
/// Backward-stable LU gives a forward error of about n eps cond(A) <= 257 * 2.2e-16 * 514
/// ~ 3e-11 in the worst case bound; typical errors are ~1e-15, so 1e-10 has margin.
#[test]
fn three_solvers_agree_with_each_other_and_with_known_solution_on_random_systems() {
    let (mut dense, mut nalg, mut sparse) =
        (FaerDenseLu::new(), NalgebraLu::new(), FaerSparseLu::new());
    for (k, &n) in SIZES.iter().enumerate() {
        let a = well_conditioned(n, 1000 + k as u64);
        let mut rng = ChaCha8Rng::seed_from_u64(k as u64);
        let x_true: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let b = matvec(&a, &x_true);
        let xd = solve_with(&mut dense, &a, &b);
        let xn = solve_with(&mut nalg, &to_nalgebra(&a), &b);
        let xs = solve_with(&mut sparse, &to_sparse(&a), &b);
        for (name, x) in [("faer dense", &xd), ("nalgebra", &xn), ("faer sparse", &xs)] {
            let e = rel_diff(x, &x_true);
            assert!(e < 1e-10, "{name}, n = {n}: relative error {e:e}");
        }
        assert!(rel_diff(&xd, &xn) < 1e-10, "n = {n}");
        assert!(rel_diff(&xs, &xd) < 1e-10, "n = {n}");
    }
}

/// The dense solvers also accept a nalgebra matrix and a faer matrix interchangeably
/// (`DenseAssemble`), with identical results for the same values.
#[test]
fn dense_solvers_accept_both_matrix_types_with_identical_results() {
    let a = well_conditioned(17, 7);
    let b: Vec<f64> = (0..17).map(|i| i as f64).collect();
    let mut lu = FaerDenseLu::new();
    let x1 = solve_with(&mut lu, &a, &b);
    let x2 = solve_with(&mut lu, &to_nalgebra(&a), &b);
    assert_eq!(x1, x2);
    let mut nlu = NalgebraLu::new();
    let y1 = solve_with(&mut nlu, &a, &b);
    let y2 = solve_with(&mut nlu, &to_nalgebra(&a), &b);
    assert_eq!(y1, y2);
}

/// The 1-D Laplacian tridiag(-1, 2, -1) of size n has the closed-form inverse
/// (A^{-1})_{ij} = min(i, j) (n + 1 - max(i, j)) / (n + 1) (1-based). Column j of the
/// inverse is the solution for b = e_j; cond(A) ~ 4 (n+1)^2 / pi^2 ~ 4e5 at n = 300, so
/// the forward error is ~ 1e-10 at worst; 1e-9 relative is the tolerance.
#[test]
fn sparse_lu_matches_closed_form_inverse_of_1d_laplacian() {
    let n = 300;
    let mut t = Vec::new();
    for i in 0..n {
        t.push(Triplet::new(i, i, 2.0));
        if i + 1 < n {
            t.push(Triplet::new(i + 1, i, -1.0));
            t.push(Triplet::new(i, i + 1, -1.0));
        }
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
    let mut lu = FaerSparseLu::new();
    lu.factor(&a).unwrap();
    for j in [0, 1, n / 2, n - 1] {
        let mut x = vec![0.0; n];
        x[j] = 1.0;
        lu.solve_in_place(&mut x).unwrap();
        let exact: Vec<f64> = (0..n)
            .map(|i| {
                let (i1, j1) = (i + 1, j + 1);
                (i1.min(j1) * (n + 1 - i1.max(j1))) as f64 / (n + 1) as f64
            })
            .collect();
        assert!(rel_diff(&x, &exact) < 1e-9, "column {j}");
    }
}

/// Refactoring with new values on the same pattern reuses the column ordering (one
/// symbolic analysis) and gives the new matrix's solution, not a stale one; a new
/// pattern factored with the old ordering is still solved exactly (the ordering only
/// affects fill), and analysing it explicitly is the second analysis.
#[test]
fn sparse_lu_analyses_each_pattern_once_and_refactors_values() {
    let mut lu = FaerSparseLu::new();
    let mut dense = FaerDenseLu::new();
    let a0 = well_conditioned(40, 1);
    let b: Vec<f64> = (0..40).map(|i| (i as f64).sin()).collect();
    for scale in [1.0, 2.0, -3.0] {
        let a = Mat::from_fn(40, 40, |i, j| scale * a0[(i, j)]);
        let xs = solve_with(&mut lu, &to_sparse(&a), &b);
        let xd = solve_with(&mut dense, &a, &b);
        assert!(rel_diff(&xs, &xd) < 1e-12, "scale {scale}");
    }
    assert_eq!(lu.symbolic_analyses(), 1);
    let tridiagonal = Mat::from_fn(40, 40, |i, j| match i.abs_diff(j) {
        0 => 4.0,
        1 => -1.0,
        _ => 0.0,
    });
    let xd = solve_with(&mut dense, &tridiagonal, &b);
    let stale = solve_with(&mut lu, &to_sparse(&tridiagonal), &b);
    assert!(rel_diff(&stale, &xd) < 1e-12);
    assert_eq!(lu.symbolic_analyses(), 1);
    lu.analyze(&to_sparse(&tridiagonal)).unwrap();
    let xs = solve_with(&mut lu, &to_sparse(&tridiagonal), &b);
    assert!(rel_diff(&xs, &xd) < 1e-12);
    assert_eq!(lu.symbolic_analyses(), 2);
}

/// A rank-2 3x3 matrix (row 3 = row 1 + row 2) is reported singular by every solver.
#[test]
fn singular_matrix_gives_typed_singular_error_for_each_solver() {
    let rows = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [5.0, 7.0, 9.0]];
    let a = Mat::from_fn(3, 3, |i, j| rows[i][j]);
    let dense = FaerDenseLu::new().factor(&a);
    let nalg = NalgebraLu::new().factor(&to_nalgebra(&a));
    let sparse = FaerSparseLu::new().factor(&to_sparse(&a));
    for (name, r) in [
        ("faer dense", dense),
        ("nalgebra", nalg),
        ("faer sparse", sparse),
    ] {
        match r {
            Err(LinearSolveError::Singular {
                pivot, max_pivot, ..
            }) => assert!(pivot <= 1e-13 * max_pivot, "{name}: {pivot} vs {max_pivot}"),
            other => panic!("{name}: expected Singular, got {other:?}"),
        }
    }
}

/// A sparse matrix with an empty column is structurally singular: faer reports it
/// and the wrapper maps it to `Singular` with pivot 0.
#[test]
fn structurally_singular_sparse_matrix_gives_singular_error() {
    let t = [Triplet::new(0, 0, 1.0), Triplet::new(1, 0, 1.0)];
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(2, 2, &t).unwrap();
    let r = FaerSparseLu::new().factor(&a);
    assert!(
        matches!(r, Err(LinearSolveError::Singular { pivot, .. }) if pivot == 0.0),
        "{r:?}"
    );
}

/// Each solver rejects a NaN or infinite entry with its position; after the error it
/// refuses to solve (no stale factorization is used).
#[test]
fn non_finite_entry_gives_typed_error_with_position_and_no_stale_solve() {
    let mut a = well_conditioned(4, 3);
    a[(2, 1)] = f64::NAN;
    let mut dense = FaerDenseLu::new();
    let mut nalg = NalgebraLu::new();
    let mut sparse = FaerSparseLu::new();
    let good = well_conditioned(4, 4);
    dense.factor(&good).unwrap();
    nalg.factor(&good).unwrap();
    sparse.factor(&to_sparse(&good)).unwrap();
    let results = [
        dense.factor(&a),
        nalg.factor(&to_nalgebra(&a)),
        sparse.factor(&to_sparse(&a)),
    ];
    for r in results {
        assert!(
            matches!(r, Err(LinearSolveError::NonFiniteEntry { row: 2, col: 1, value }) if value.is_nan()),
            "{r:?}"
        );
    }
    let mut x = [1.0; 4];
    assert_eq!(
        dense.solve_in_place(&mut x),
        Err(LinearSolveError::NotFactored)
    );
    assert_eq!(
        nalg.solve_in_place(&mut x),
        Err(LinearSolveError::NotFactored)
    );
    assert_eq!(
        sparse.solve_in_place(&mut x),
        Err(LinearSolveError::NotFactored)
    );
    a[(2, 1)] = f64::INFINITY;
    assert!(matches!(
        FaerDenseLu::new().factor(&a),
        Err(LinearSolveError::NonFiniteEntry { row: 2, col: 1, .. })
    ));
}

/// Misuse is a typed error: solving before factoring, a right-hand side of the wrong
/// length, a non-square sparse matrix.
#[test]
fn misuse_gives_typed_errors() {
    let mut x = [0.0; 3];
    assert_eq!(
        FaerDenseLu::new().solve_in_place(&mut x),
        Err(LinearSolveError::NotFactored)
    );
    assert_eq!(
        NalgebraLu::new().solve_in_place(&mut x),
        Err(LinearSolveError::NotFactored)
    );
    assert_eq!(
        FaerSparseLu::new().solve_in_place(&mut x),
        Err(LinearSolveError::NotFactored)
    );
    let a = well_conditioned(2, 5);
    let mut lu = FaerDenseLu::new();
    lu.factor(&a).unwrap();
    assert_eq!(
        lu.solve_in_place(&mut x),
        Err(LinearSolveError::DimensionMismatch {
            expected: 2,
            found: 3
        })
    );
    let rect = SparseColMat::<usize, f64>::try_new_from_triplets(2, 3, &[Triplet::new(0, 0, 1.0)])
        .unwrap();
    assert_eq!(
        FaerSparseLu::new().factor(&rect),
        Err(LinearSolveError::DimensionMismatch {
            expected: 2,
            found: 3
        })
    );
}

/// A zero-size system is valid and trivially solved by each solver.
#[test]
fn empty_system_is_trivially_solved() {
    let a = Mat::<f64>::zeros(0, 0);
    let mut x: [f64; 0] = [];
    let mut d = FaerDenseLu::new();
    d.factor(&a).unwrap();
    d.solve_in_place(&mut x).unwrap();
    let mut n = NalgebraLu::new();
    n.factor(&to_nalgebra(&a)).unwrap();
    n.solve_in_place(&mut x).unwrap();
    let mut s = FaerSparseLu::new();
    s.factor(&to_sparse(&a)).unwrap();
    s.solve_in_place(&mut x).unwrap();
}

/// A matrix that only claims a size: 2^26 rows, whose dense factors (2^52 numbers, 32 PiB)
/// cannot be allocated anywhere.
struct Enormous;

impl semismooth::linalg::DenseAssemble for Enormous {
    fn dim(&self) -> usize {
        1 << 26
    }
    fn assemble_dense(&self, _out: faer::MatMut<'_, f64>) {
        unreachable!("the factors cannot be allocated")
    }
}

#[test]
fn a_dense_matrix_too_large_for_memory_is_a_typed_out_of_memory_error() {
    let mut lu = FaerDenseLu::new();
    let err = lu.factor(&Enormous).unwrap_err();
    assert!(
        matches!(err, LinearSolveError::OutOfMemory { .. }),
        "{err:?}"
    );
    assert_eq!(err.kind(), "out-of-memory");
    // The solver stays usable: a small system factors and solves afterwards.
    let a = well_conditioned(5, 7);
    let b = vec![1.0; 5];
    let x = solve_with(&mut lu, &a, &b);
    assert!(rel_diff(&matvec(&a, &x), &b) < 1e-12);
}
