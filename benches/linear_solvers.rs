//! Baseline for the linear solvers: factor + solve of a "tridiagonal-ish" system
//! (tridiagonal plus a periodic corner coupling, diagonally dominant) with faer dense
//! LU, nalgebra LU and faer sparse LU, sequential.
//!
//! `cargo bench --bench linear_solvers` (all), or e.g. `-- sparse` for one group. Groups:
//! - `factor_solve/{faer_dense,nalgebra,faer_sparse}/n`: repeated factor + one solve
//!   with a reused solver (for the sparse LU: numeric refactorization, the column ordering
//!   is computed once), n = 50 .. 2000 (nalgebra up to 1000);
//! - `sparse_first_factor/n`: a fresh sparse solver each time (ordering + numeric);
//! - `sparse_large/100000`: the sparse path at n = 1e5 (refactor + solve).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Par};
use semismooth::linalg::{FaerDenseLu, FaerSparseLu, NalgebraLu};
use semismooth::Factorize;

/// tridiag(-1, 4, -1) plus entries (0, n-1) and (n-1, 0) equal to -1 (periodic chain).
fn triplets(n: usize) -> Vec<Triplet<usize, usize, f64>> {
    let mut t = Vec::with_capacity(3 * n + 2);
    for i in 0..n {
        t.push(Triplet::new(i, i, 4.0 + (i % 7) as f64 * 0.01));
        if i + 1 < n {
            t.push(Triplet::new(i + 1, i, -1.0));
            t.push(Triplet::new(i, i + 1, -1.0));
        }
    }
    if n > 2 {
        t.push(Triplet::new(0, n - 1, -1.0));
        t.push(Triplet::new(n - 1, 0, -1.0));
    }
    t
}

fn sparse(n: usize) -> SparseColMat<usize, f64> {
    SparseColMat::try_new_from_triplets(n, n, &triplets(n)).expect("valid triplets")
}

fn dense(n: usize) -> Mat<f64> {
    let mut a = Mat::zeros(n, n);
    for t in triplets(n) {
        a[(t.row, t.col)] += t.val;
    }
    a
}

fn rhs(n: usize) -> Vec<f64> {
    (0..n).map(|i| (i as f64 * 0.37).sin()).collect()
}

/// One timed iteration: factor `a` with the reused solver, solve for `b` into `x`.
fn factor_and_solve<J, S: Factorize<J>>(lu: &mut S, a: &J, b: &[f64], x: &mut [f64]) {
    lu.factor(a).expect("regular");
    x.copy_from_slice(b);
    lu.solve_in_place(x).expect("factored");
    black_box(x);
}

fn factor_solve(c: &mut Criterion) {
    faer::set_global_parallelism(Par::Seq);
    let mut group = c.benchmark_group("factor_solve");
    group.sample_size(10);
    for n in [50, 100, 200, 500, 1000, 2000] {
        let a = dense(n);
        let b = rhs(n);
        let mut x = b.clone();
        let mut lu = FaerDenseLu::new();
        group.bench_with_input(BenchmarkId::new("faer_dense", n), &n, |bench, _| {
            bench.iter(|| factor_and_solve(&mut lu, &a, &b, &mut x))
        });
        if n <= 1000 {
            let an = nalgebra::DMatrix::from_fn(n, n, |i, j| a[(i, j)]);
            let mut lu = NalgebraLu::new();
            group.bench_with_input(BenchmarkId::new("nalgebra", n), &n, |bench, _| {
                bench.iter(|| factor_and_solve(&mut lu, &an, &b, &mut x))
            });
        }
        let s = sparse(n);
        let mut lu = FaerSparseLu::new();
        group.bench_with_input(BenchmarkId::new("faer_sparse", n), &n, |bench, _| {
            bench.iter(|| factor_and_solve(&mut lu, &s, &b, &mut x))
        });
    }
    group.finish();

    let mut group = c.benchmark_group("sparse_first_factor");
    group.sample_size(10);
    for n in [100, 1000] {
        let s = sparse(n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| {
                let mut lu = FaerSparseLu::new();
                lu.factor(&s).expect("regular");
                black_box(lu.symbolic_analyses());
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("sparse_large");
    group.sample_size(10);
    let n = 100_000;
    let s = sparse(n);
    let b = rhs(n);
    let mut x = b.clone();
    let mut lu = FaerSparseLu::new();
    group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
        bench.iter(|| factor_and_solve(&mut lu, &s, &b, &mut x))
    });
    group.finish();
}

criterion_group!(benches, factor_solve);
criterion_main!(benches);
