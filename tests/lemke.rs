//! Lemke's method checked against independent answers: enumeration of active sets,
//! projected Gauss–Seidel on the equivalent QP, closed forms, and theory (rays on
//! infeasible copositive-plus LCPs).

mod common;

use common::allocations;
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use semismooth::lemke::{
    complementarity_error, solve_lcp, LcpVariable, Lemke, LemkeError, LemkeOptions,
    LemkeTermination,
};
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::Tolerances;
use semismooth::polyalgorithm::{solve, PolyalgorithmOptions};
use semismooth::InvalidOption;
use semismooth::{EvaluationError, GeneralizedJacobian, Residual};

#[global_allocator]
static GLOBAL: common::CountingAllocator = common::CountingAllocator;

fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Strictly row-diagonally-dominant matrix with positive diagonal and off-diagonal
/// entries of random sign: a (non-symmetric) P-matrix.
fn dominant_p_matrix(n: usize, rng: &mut ChaCha8Rng) -> Mat<f64> {
    let mut m = Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0_f64));
    for i in 0..n {
        let off: f64 = (0..n).filter(|&j| j != i).map(|j| m[(i, j)].abs()).sum();
        m[(i, i)] = off + rng.random_range(0.2..1.5);
    }
    m
}

/// `A A^T / n + shift I` with A uniform in [-1, 1]: symmetric positive definite,
/// eigenvalues in `[shift, shift + n/3 + ...]`.
fn spd_matrix(n: usize, shift: f64, rng: &mut ChaCha8Rng) -> Mat<f64> {
    let a = Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0_f64));
    let mut m = &a * a.transpose();
    for j in 0..n {
        for i in 0..n {
            m[(i, j)] /= n as f64;
        }
        m[(j, j)] += shift;
    }
    m
}

/// `S + K` with `S` symmetric positive definite and `K` skew-symmetric: positive
/// definite but not symmetric, hence a P-matrix.
fn pd_nonsymmetric(n: usize, rng: &mut ChaCha8Rng) -> Mat<f64> {
    let mut m = spd_matrix(n, 0.3, rng);
    for j in 0..n {
        for i in 0..j {
            let k = rng.random_range(-1.0..1.0);
            m[(i, j)] += k;
            m[(j, i)] -= k;
        }
    }
    m
}

/// All solutions of the LCP found by enumerating the `2^n` active sets `a`:
/// `M_aa z_a = -q_a`, accepted when `z_a >= -feas` and `w = q + M z >= -feas`.
fn enumerate_solutions(m: &Mat<f64>, q: &[f64], feas: f64) -> Vec<Vec<f64>> {
    let n = q.len();
    let mut solutions = Vec::new();
    for mask in 0u32..(1u32 << n) {
        let set: Vec<usize> = (0..n).filter(|&i| mask & (1 << i) != 0).collect();
        let k = set.len();
        let mut z = vec![0.0; n];
        if k > 0 {
            let sub = Mat::from_fn(k, k, |a, b| m[(set[a], set[b])]);
            let mut rhs = Mat::from_fn(k, 1, |a, _| -q[set[a]]);
            let lu = PartialPivLu::new(sub.as_ref());
            lu.solve_in_place(rhs.as_mut());
            if (0..k).any(|a| !rhs[(a, 0)].is_finite()) {
                continue;
            }
            for (a, &i) in set.iter().enumerate() {
                z[i] = rhs[(a, 0)];
            }
        }
        let w = residual(m, q, &z);
        if z.iter().all(|&v| v >= -feas) && w.iter().all(|&v| v >= -feas) {
            solutions.push(z);
        }
    }
    solutions
}

/// `q + M z`.
fn residual(m: &Mat<f64>, q: &[f64], z: &[f64]) -> Vec<f64> {
    (0..q.len())
        .map(|i| q[i] + (0..q.len()).map(|j| m[(i, j)] * z[j]).sum::<f64>())
        .collect()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |acc, (x, y)| acc.max((x - y).abs()))
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0_f64, |acc, x| acc.max(x.abs()))
}

/// Tolerance of the agreement tests: the matrices are well conditioned (condition number
/// below about 1e2: dominant diagonals, eigenvalues bounded below by 0.2-0.3), both the
/// LU of the enumeration and Lemke's product-form inverse (at most a few dozen pivots for
/// n <= 8, then refined) are backward stable with errors of order n * cond * eps ~ 1e-13;
/// 1e-10 relative leaves three orders of margin and would still catch any wrong active set
/// (which moves z by O(1)).
const AGREEMENT: f64 = 1e-10;

fn check_against_enumeration(m: &Mat<f64>, q: &[f64], lemke: &mut Lemke, label: &str) {
    let report = lemke
        .solve(m.as_ref(), q, &LemkeOptions::default())
        .unwrap();
    assert_eq!(report.termination, LemkeTermination::Solved, "{label}");
    let feas = 1e-12 * (1.0 + max_abs(q));
    let solutions = enumerate_solutions(m, q, feas);
    assert!(!solutions.is_empty(), "{label}: enumeration found nothing");
    // A P-matrix LCP has exactly one solution (degenerate ones may be found from
    // several active sets, all equal).
    for s in &solutions {
        assert!(
            max_abs_diff(s, &solutions[0]) <= 1e-9 * (1.0 + max_abs(s)),
            "{label}"
        );
    }
    let reference = &solutions[0];
    let diff = max_abs_diff(&report.z, reference);
    assert!(
        diff <= AGREEMENT * (1.0 + max_abs(reference)),
        "{label}: lemke z = {:?}, enumeration z = {reference:?}, diff {diff:e}",
        report.z
    );
    let w = residual(m, q, &report.z);
    assert!(
        max_abs_diff(&w, &report.w) <= 1e-12 * (1.0 + max_abs(&w)),
        "{label}"
    );
    assert!(
        report.complementarity_error <= 1e-12 * (1.0 + max_abs(q)),
        "{label}"
    );
    assert_eq!(report.artificial, 0.0, "{label}");
}

#[test]
fn agrees_with_enumeration_on_random_p_matrix_lcps_up_to_n8() {
    // One workspace for all sizes: also checks resizing and reuse.
    let mut lemke = Lemke::new(3);
    for n in 1..=8 {
        for seed in 0..60u64 {
            let mut r = rng(1000 * n as u64 + seed);
            let m = match seed % 3 {
                0 => dominant_p_matrix(n, &mut r),
                1 => spd_matrix(n, 0.2, &mut r),
                _ => pd_nonsymmetric(n, &mut r),
            };
            let q: Vec<f64> = (0..n).map(|_| r.random_range(-2.0..1.0)).collect();
            check_against_enumeration(&m, &q, &mut lemke, &format!("n={n} seed={seed}"));
        }
    }
}

#[test]
fn workspace_reuse_gives_the_same_answer_as_a_fresh_workspace() {
    let mut lemke = Lemke::new(0);
    for (k, n) in [5usize, 2, 7, 7, 1, 5].into_iter().enumerate() {
        let mut r = rng(77 + k as u64);
        let m = pd_nonsymmetric(n, &mut r);
        let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
        let reused = lemke
            .solve(m.as_ref(), &q, &LemkeOptions::default())
            .unwrap();
        let fresh = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
        assert_eq!(reused, fresh, "n = {n}");
        assert_eq!(lemke.dim(), n);
    }
}

/// With a workspace of the right size, a solve allocates only the two vectors of its
/// report (`z` and `w`), however many pivots it makes.
#[test]
fn solve_allocates_only_the_report_whatever_the_pivot_count() {
    let mut lemke = Lemke::new(300);
    let options = LemkeOptions::default();
    for (seed, n) in [(1u64, 300usize), (2, 300), (3, 300)] {
        let mut r = rng(seed);
        let m = spd_matrix(n, 1.0, &mut r);
        let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..0.5)).collect();
        let before = allocations();
        let report = lemke.solve(m.as_ref(), &q, &options).unwrap();
        let count = allocations() - before;
        assert!(
            report.solved() && report.pivots > 100,
            "pivots {}",
            report.pivots
        );
        assert_eq!(count, 2, "{count} allocations for {} pivots", report.pivots);
    }
}

/// A row-major view (`M^T` of a column-major matrix) goes through the strided column
/// path; it must give exactly what the contiguous copy gives.
#[test]
fn strided_matrix_view_gives_the_same_report_as_a_contiguous_copy() {
    let mut r = rng(31);
    let n = 9;
    let a = pd_nonsymmetric(n, &mut r);
    let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
    let view = a.transpose();
    let copy = view.to_owned();
    let strided = solve_lcp(view, &q, &LemkeOptions::default()).unwrap();
    let contiguous = solve_lcp(copy.as_ref(), &q, &LemkeOptions::default()).unwrap();
    assert!(strided.solved());
    assert_eq!(strided, contiguous);
}

#[test]
fn empty_lcp_is_solved_trivially() {
    let m = Mat::<f64>::zeros(0, 0);
    let report = solve_lcp(m.as_ref(), &[], &LemkeOptions::default()).unwrap();
    assert_eq!(report.termination, LemkeTermination::Solved);
    assert_eq!((report.pivots, report.z.len()), (0, 0));
}

#[test]
fn q_nonnegative_is_solved_by_zero_without_pivots() {
    let mut r = rng(5);
    let m = dominant_p_matrix(4, &mut r);
    let q = [0.0, 1.0, 2.5, 0.0];
    let report = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
    assert_eq!(report.termination, LemkeTermination::Solved);
    assert_eq!(report.pivots, 0);
    assert_eq!(report.z, vec![0.0; 4]);
    assert_eq!(report.w, q.to_vec());
    assert_eq!(report.complementarity_error, 0.0);
}

#[test]
fn custom_covering_vector_gives_the_same_unique_solution() {
    for seed in 0..20u64 {
        let mut r = rng(300 + seed);
        let n = 6;
        let m = dominant_p_matrix(n, &mut r);
        let q: Vec<f64> = (0..n).map(|_| r.random_range(-2.0..1.0)).collect();
        let d: Vec<f64> = (0..n).map(|_| r.random_range(0.1..3.0)).collect();
        let ones = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
        let options = LemkeOptions {
            covering: Some(d),
            ..LemkeOptions::default()
        };
        let custom = solve_lcp(m.as_ref(), &q, &options).unwrap();
        assert!(ones.solved() && custom.solved());
        // Unique solution of a P-matrix LCP: the covering vector changes the path only.
        assert!(max_abs_diff(&ones.z, &custom.z) <= AGREEMENT * (1.0 + max_abs(&ones.z)));
    }
}

/// The fully tied instance `M = [[1,2,0],[0,1,2],[2,0,1]]`, `q = -(1,1,1)` (Murty,
/// *Linear Complementarity...*, 1988, the standard degenerate example for Lemke's
/// method with covering vector ones): every ratio of the first pivot ties. M is a
/// P-matrix (principal minors 1, 1, 1, 1, 1, 1, 9), so the unique solution is
/// `z = (1,1,1)/3`, `w = 0` (check: `-1 + 1/3 + 2/3 = 0`). A smallest-index tie-break
/// on this cyclic matrix can revisit bases; the lexicographic rule cannot.
#[test]
fn degenerate_tied_instance_is_solved_without_cycling() {
    let rows = [[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]];
    let m = Mat::from_fn(3, 3, |i, j| rows[i][j]);
    let q = [-1.0, -1.0, -1.0];
    let report = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
    assert_eq!(report.termination, LemkeTermination::Solved);
    // Lexicographic pivoting visits each almost-complementary basis at most once; there
    // are at most 2^3 complementary pairs times 4 positions of z0: far below the limit.
    assert!(report.pivots <= 8, "pivots = {}", report.pivots);
    for &z in &report.z {
        assert!((z - 1.0 / 3.0).abs() <= 1e-14, "z = {:?}", report.z);
    }
    assert!(report.complementarity_error <= 1e-14);
}

/// Heavily degenerate LCPs: small integer P-matrices (diagonally dominant) with `q` in
/// `{-1, 0, 1}` (zeros and ties everywhere, degenerate solutions). Lemke must end solved,
/// within a pivot count far below the limit, on the unique solution found by enumeration.
#[test]
fn degenerate_integer_lcps_with_ties_and_zeros_terminate_on_the_unique_solution() {
    let mut lemke = Lemke::new(6);
    let mut max_pivots = 0;
    for seed in 0..400u64 {
        let mut r = rng(9000 + seed);
        let n = 2 + (seed as usize % 5);
        let mut m = Mat::from_fn(n, n, |_, _| r.random_range(-1i32..=1) as f64);
        for i in 0..n {
            let off: f64 = (0..n).filter(|&j| j != i).map(|j| m[(i, j)].abs()).sum();
            m[(i, i)] = off + 1.0;
        }
        let mut q: Vec<f64> = (0..n).map(|_| r.random_range(-1i32..=1) as f64).collect();
        q[0] = -1.0; // never the trivial q >= 0
        let report = lemke
            .solve(m.as_ref(), &q, &LemkeOptions::default())
            .unwrap();
        assert_eq!(report.termination, LemkeTermination::Solved, "seed {seed}");
        max_pivots = max_pivots.max(report.pivots);
        let solutions = enumerate_solutions(&m, &q, 1e-12);
        assert!(!solutions.is_empty());
        let diff = max_abs_diff(&report.z, &solutions[0]);
        assert!(
            diff <= 1e-12,
            "seed {seed}: {:?} vs {:?}",
            report.z,
            solutions[0]
        );
        assert!(report.complementarity_error <= 1e-12);
    }
    // Without anti-cycling a cycle would run into the limit of 50 n + 100 >= 200 pivots.
    assert!(max_pivots <= 4 * 6, "max pivots {max_pivots}");
}

/// A degenerate symmetric case: `M = ones + I` couples every unknown equally, `q` has
/// ties; solution by symmetry `z_i = 1/(n+1)` on the tied set.
#[test]
fn degenerate_symmetric_all_tied_lcp_has_the_symmetric_solution() {
    let n = 6;
    let m = Mat::from_fn(n, n, |i, j| if i == j { 2.0 } else { 1.0 });
    let q = vec![-1.0; n];
    let report = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
    assert_eq!(report.termination, LemkeTermination::Solved);
    // w_i = -1 + z_i + sum_j z_j = 0 with all z equal: z (1 + n) = 1.
    for &z in &report.z {
        assert!((z - 1.0 / (n as f64 + 1.0)).abs() <= 1e-14);
    }
    assert!(report.pivots <= n + 1);
}

#[test]
fn infeasible_lcps_end_on_a_secondary_ray() {
    // (a) M = [-1], q = -1: w = -1 - z < 0 for every z >= 0.
    // (b) M = [[1,-1],[-1,1]] (positive semidefinite, hence copositive-plus), q = -(1,1):
    //     w_1 + w_2 = -2 < 0, infeasible; theory says Lemke must end on a ray.
    // (c) M = [[0,-1],[1,0]] (skew, copositive-plus), q = -(1,1): w_1 = -1 - z_2 < 0.
    let cases: Vec<(Mat<f64>, Vec<f64>)> = vec![
        (Mat::from_fn(1, 1, |_, _| -1.0), vec![-1.0]),
        (
            Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { -1.0 }),
            vec![-1.0, -1.0],
        ),
        (
            Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => -1.0,
                (1, 0) => 1.0,
                _ => 0.0,
            }),
            vec![-1.0, -1.0],
        ),
    ];
    for (k, (m, q)) in cases.iter().enumerate() {
        let report = solve_lcp(m.as_ref(), q, &LemkeOptions::default()).unwrap();
        assert_eq!(report.termination, LemkeTermination::Ray, "case {k}");
        assert!(report.pivots >= 1 && report.pivots <= 4, "case {k}");
        assert!(matches!(
            report.ray_entering,
            Some(LcpVariable::Z(_)) | Some(LcpVariable::W(_))
        ));
        // The artificial variable is still positive: no solution was found.
        assert!(report.artificial > 0.0, "case {k}");
        assert!(report.complementarity_error > 0.1, "case {k}");
        assert!(report.clone().into_result().is_err());
    }
    // (a) in detail: z0 enters and w_1 leaves; then z_1 enters with column
    // B^{-1}(-M e_1) = (-1)^{-1} (1) < 0: unblocked after one pivot.
    let report = solve_lcp(cases[0].0.as_ref(), &cases[0].1, &LemkeOptions::default()).unwrap();
    assert_eq!(report.pivots, 1);
    assert_eq!(report.ray_entering, Some(LcpVariable::Z(0)));
    assert_eq!(report.artificial, 1.0);
}

#[test]
fn pivot_limit_is_reported_as_an_outcome() {
    let mut r = rng(11);
    let n = 8;
    let m = spd_matrix(n, 0.5, &mut r);
    let q = vec![-1.0; n];
    let full = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
    assert!(full.solved() && full.pivots > 3);
    for limit in [0, 1, 2, 3] {
        let options = LemkeOptions {
            max_pivots: Some(limit),
            ..LemkeOptions::default()
        };
        let report = solve_lcp(m.as_ref(), &q, &options).unwrap();
        assert_eq!(report.termination, LemkeTermination::PivotLimit);
        assert_eq!(report.pivots, limit);
        assert!(report.z.iter().all(|v| v.is_finite()));
        assert!(matches!(
            report.into_result(),
            Err(LemkeError::NotSolved {
                termination: LemkeTermination::PivotLimit,
                ..
            })
        ));
    }
}

/// For symmetric positive definite M the LCP is the optimality system of
/// `min 0.5 z'Mz + q'z, z >= 0`; projected Gauss–Seidel solves that QP independently.
#[test]
fn spd_lcp_agrees_with_projected_gauss_seidel_on_the_equivalent_qp() {
    for seed in 0..5u64 {
        let mut r = rng(500 + seed);
        let n = 40;
        let m = spd_matrix(n, 1.0, &mut r);
        let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
        let mut z = vec![0.0; n];
        let mut sweeps = 0;
        loop {
            let mut change = 0.0_f64;
            for i in 0..n {
                let s: f64 = q[i] + (0..n).map(|j| m[(i, j)] * z[j]).sum::<f64>();
                let new = (z[i] - s / m[(i, i)]).max(0.0);
                change = change.max((new - z[i]).abs());
                z[i] = new;
            }
            sweeps += 1;
            if change < 1e-15 || sweeps > 100_000 {
                break;
            }
        }
        // PGS stopped on a fixed point to 1e-15; for eigenvalues of M >= 1 the distance
        // to the solution is bounded by a modest multiple of that.
        let pgs_error = complementarity_error(&z, &residual(&m, &q, &z));
        assert!(pgs_error < 1e-13, "PGS did not converge: {pgs_error:e}");
        let report = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
        assert!(report.solved());
        let diff = max_abs_diff(&report.z, &z);
        assert!(
            diff <= AGREEMENT * (1.0 + max_abs(&z)),
            "seed {seed}: diff {diff:e}"
        );
    }
}

#[test]
fn bad_inputs_give_typed_errors() {
    let m = Mat::<f64>::identity(3, 3);
    let options = LemkeOptions::default();
    let mut lemke = Lemke::new(3);
    assert_eq!(
        lemke.solve(m.as_ref(), &[1.0, 2.0], &options),
        Err(LemkeError::DimensionMismatch {
            what: "q",
            expected: 3,
            found: 2
        })
    );
    let rect = Mat::<f64>::zeros(3, 2);
    assert_eq!(
        lemke.solve(rect.as_ref(), &[1.0, 2.0, 3.0], &options),
        Err(LemkeError::DimensionMismatch {
            what: "columns of M",
            expected: 3,
            found: 2
        })
    );
    let mut bad = m.clone();
    bad[(2, 1)] = f64::NAN;
    match lemke.solve(bad.as_ref(), &[-1.0, 2.0, 3.0], &options) {
        Err(LemkeError::NonFiniteMatrixEntry {
            row: 2,
            col: 1,
            value,
        }) => {
            assert!(value.is_nan())
        }
        other => panic!("expected NonFiniteMatrixEntry, got {other:?}"),
    }
    assert_eq!(
        lemke.solve(m.as_ref(), &[-1.0, f64::INFINITY, 3.0], &options),
        Err(LemkeError::NonFiniteVectorEntry {
            name: "q",
            index: 1,
            value: f64::INFINITY
        })
    );
    for tolerance in [0.0, -1.0, 1.0, f64::NAN] {
        let o = LemkeOptions {
            tolerance,
            ..LemkeOptions::default()
        };
        assert!(matches!(
            lemke.solve(m.as_ref(), &[-1.0, 2.0, 3.0], &o),
            Err(LemkeError::InvalidOption(InvalidOption {
                name: "tolerance",
                ..
            }))
        ));
    }
    let o = LemkeOptions {
        covering: Some(vec![1.0, 0.0, 1.0]),
        ..LemkeOptions::default()
    };
    assert_eq!(
        lemke.solve(m.as_ref(), &[-1.0, 2.0, 3.0], &o),
        Err(LemkeError::InvalidCovering {
            index: 1,
            value: 0.0
        })
    );
    let o = LemkeOptions {
        covering: Some(vec![1.0, 1.0]),
        ..LemkeOptions::default()
    };
    assert_eq!(
        lemke.solve(m.as_ref(), &[-1.0, 2.0, 3.0], &o),
        Err(LemkeError::DimensionMismatch {
            what: "covering",
            expected: 3,
            found: 2
        })
    );
    // After all these refusals the workspace still works.
    let report = lemke
        .solve(m.as_ref(), &[-1.0, 2.0, -3.0], &options)
        .unwrap();
    assert_eq!(report.z, vec![1.0, 0.0, 3.0]);
}

/// n = 1024, `M = A A^T / n + I` (eigenvalues in [1, ~5]), q uniform in [-1, 1]:
/// roughly half the constraints active, hundreds of pivots.
#[test]
fn large_spd_lcp_n1024_has_small_complementarity_error() {
    let mut r = rng(2024);
    let n = 1024;
    let m = spd_matrix(n, 1.0, &mut r);
    let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
    let report = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).unwrap();
    assert_eq!(report.termination, LemkeTermination::Solved);
    assert!(
        report.complementarity_error < 1e-9,
        "error {:e} after {} pivots",
        report.complementarity_error,
        report.pivots
    );
    let active = report.z.iter().filter(|&&z| z > 0.0).count();
    assert!(active > n / 8, "only {active} active");
}

/// `F(z) = min(z, q + M z)`: its zeros are the solutions of the LCP.
struct MinMap<'a> {
    m: &'a Mat<f64>,
    q: &'a [f64],
}

impl Residual for MinMap<'_> {
    fn dim(&self) -> usize {
        self.q.len()
    }
    fn residual(&mut self, z: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let w = residual(self.m, self.q, z);
        for i in 0..z.len() {
            out[i] = z[i].min(w[i]);
        }
        Ok(())
    }
}

impl GeneralizedJacobian for MinMap<'_> {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.q.len(), self.q.len())
    }
    fn jacobian(&mut self, z: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        let n = z.len();
        let w = residual(self.m, self.q, z);
        for i in 0..n {
            for j in 0..n {
                // Row of I where z_i <= w_i, row of M otherwise.
                jac[(i, j)] = if z[i] <= w[i] {
                    (i == j) as u8 as f64
                } else {
                    self.m[(i, j)]
                };
            }
        }
        Ok(())
    }
}

/// Lemke and the semismooth Newton method on `min(z, q + M z) = 0` give the same
/// solution. Newton stops at `|F|_2 <= 1e-13`; for these well-conditioned P-matrices (and
/// once the active set is right Newton is exact up to rounding) the distance to the
/// solution is of the same order, far below the 1e-10 agreement tolerance.
#[test]
fn lemke_agrees_with_semismooth_newton_on_the_min_map() {
    let options = PolyalgorithmOptions {
        tolerances: Tolerances::absolute(1e-13),
        ..PolyalgorithmOptions::default()
    };
    let mut lemke = Lemke::new(8);
    for seed in 0..60u64 {
        let mut r = rng(4242 + seed);
        let n = [1usize, 2, 3, 5, 8, 20, 60][seed as usize % 7];
        let m = if seed % 2 == 0 {
            dominant_p_matrix(n, &mut r)
        } else {
            spd_matrix(n, 0.5, &mut r)
        };
        let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
        let report = lemke
            .solve(m.as_ref(), &q, &LemkeOptions::default())
            .unwrap();
        assert!(report.solved());
        let mut z = vec![0.0; n];
        let newton = solve(
            &mut MinMap { m: &m, q: &q },
            &mut FaerDenseLu::new(),
            &mut z,
            &options,
        )
        .unwrap();
        assert!(newton.converged(), "seed {seed}: {:?}", newton.termination);
        let diff = max_abs_diff(&report.z, &z);
        assert!(
            diff <= AGREEMENT * (1.0 + max_abs(&z)),
            "seed {seed} n {n}: diff {diff:e}"
        );
    }
}

#[allow(dead_code)]
#[path = "../examples/custom_problem.rs"]
mod custom_problem;

/// The example `custom_problem` (spring chain between two walls) run as a test: the
/// Newton solution of the full problem and Lemke on the condensed LCP agree to 1e-9 (the
/// example's own exit criterion), the Lemke answer satisfies the full residual, and the
/// three loads give the three contact states.
#[test]
fn custom_problem_newton_agrees_with_lemke_in_every_contact_state() {
    for (load, closed) in [
        (0.1, [false, false]),
        (0.3, [false, true]),
        (2.0, [true, true]),
    ] {
        let mut chain = custom_problem::SpringChain::new(12, 100.0, 1.0, load, [0.02, 0.05]);
        let [x, y] = custom_problem::newton_and_lemke(&mut chain).unwrap();
        let diff = max_abs_diff(&x, &y);
        assert!(diff <= 1e-9, "load {load}: difference {diff:e}");
        let mut f = vec![0.0; y.len()];
        chain.residual(&y, &mut f).unwrap();
        println!(
            "load {load}: difference {diff:e}, residual {:e}",
            max_abs(&f)
        );
        // Forces of order 1, stiffness 100: rounding leaves residuals ~1e-14 (measured
        // 8.3e-16, 1.5e-15, 1.6e-14 at the three loads); allowed 3 times the largest.
        assert!(
            max_abs(&f) <= 5e-14,
            "load {load}: residual {:e}",
            max_abs(&f)
        );
        let n = y.len() - 2;
        assert_eq!(
            [y[n] > 0.0, y[n + 1] > 0.0],
            closed,
            "load {load}: {:?}",
            &y[n..]
        );
    }
}
