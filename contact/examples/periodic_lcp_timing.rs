//! The periodic LCP's solvers at work (nothing asserted; `contact/tests/periodic_lcp.rs`
//! checks correctness):
//! 1. Lemke's algorithm at n = 2048: wall and CPU time, pivots and complementarity error on
//!    the periodic LCP of the canonical rod (both mass models), a circulant stand-in and a
//!    random symmetric positive definite LCP;
//! 2. the canonical rod's LCP against `Nt` = 128 ... 2048 for the three mass models: the
//!    spectrum of the symmetric part of `A`, Lemke (pivot limit `100 n`) and semismooth
//!    Newton on the min-map from zero and by mesh sequencing (the library's
//!    `solve_min_map_sequenced`), with their tip minima and the distance between the answers;
//!    and Lemke on the undamped rod, whose `A` is not copositive-plus.
//!
//! `cargo run --release -p semismooth-contact --example periodic_lcp_timing` (a few minutes)

use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use semismooth::lemke::{Lemke, LemkeOptions};
use semismooth::polyalgorithm::{self, PolyalgorithmOptions, SolveOptions};
use semismooth_contact::lcp::{
    solve_min_map_sequenced, ActiveSetSolver, PeriodicLcp, PeriodicLcpOptions,
    DEFAULT_ACTIVE_SET_REGULARIZATION,
};
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};

/// CPU time of the current thread in seconds (Linux; NaN elsewhere).
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// `A A^T / n + I`, `A` with uniform entries in `[-1, 1)`: symmetric positive definite.
fn spd_matrix(n: usize, rng: &mut ChaCha8Rng) -> Mat<f64> {
    let a = Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0_f64));
    let mut m = &a * a.transpose();
    for j in 0..n {
        for i in 0..n {
            m[(i, j)] /= n as f64;
        }
        m[(j, j)] += 1.0;
    }
    m
}

/// Periodic-LCP stand-in for timing: a symmetric positive definite circulant matrix
/// (exponential kernel plus identity) and `q_i = 0.5 - cos(2 pi i / n)` (a gap of 0.5
/// closed by a harmonic motion of amplitude 1: about a third of the period in contact).
fn circulant_case(n: usize) -> (Mat<f64>, Vec<f64>) {
    let kernel = |k: usize| {
        let d = k.min(n - k) as f64;
        (-d / (0.02 * n as f64)).exp()
    };
    let m = Mat::from_fn(n, n, |i, j| {
        let k = (i + n - j) % n;
        kernel(k) / (0.02 * n as f64) + if k == 0 { 1.0 } else { 0.0 }
    });
    let q = (0..n)
        .map(|i| 0.5 - (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos())
        .collect();
    (m, q)
}

fn lemke_at_2048() {
    let n = 2048;
    let mut lemke = Lemke::new(n);
    let mut timed = |label: &str, m: faer::MatRef<'_, f64>, q: &[f64]| {
        let start = std::time::Instant::now();
        let cpu = thread_cpu_seconds();
        let report = lemke.solve(m, q, &LemkeOptions::default()).unwrap();
        let cpu = thread_cpu_seconds() - cpu;
        println!(
            "{label} n={}: {:?}, {} pivots, {} active, error {:e}, wall {:.3} s, cpu {cpu:.3} s",
            q.len(),
            report.termination,
            report.pivots,
            report.z.iter().filter(|&&z| z > 0.0).count(),
            report.complementarity_error,
            start.elapsed().as_secs_f64()
        );
    };
    for mass in [MassModel::Modified, MassModel::Consistent] {
        let lcp = periodic_lcp(&rod(mass, true), n);
        timed(
            &format!("canonical rod, {mass:?} mass"),
            lcp.matrix(),
            lcp.q(),
        );
    }
    let (m, q) = circulant_case(n);
    timed("circulant", m.as_ref(), &q);
    timed("circulant (reused workspace)", m.as_ref(), &q);
    let mut r = ChaCha8Rng::seed_from_u64(7);
    let m = spd_matrix(n, &mut r);
    let q: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
    timed("random SPD", m.as_ref(), &q);
}

/// The canonical rod with the mass model `mass`, damped as the canonical one or undamped.
fn rod(mass: MassModel, damped: bool) -> RodModel {
    let mut spec = RodSpec {
        mass,
        ..RodSpec::canonical()
    };
    if !damped {
        spec.damping = None;
    }
    build_rod(&spec).unwrap()
}

/// The periodic LCP of `rod` at its frequency on `nt` time samples.
fn periodic_lcp(rod: &RodModel, nt: usize) -> PeriodicLcp {
    let options = PeriodicLcpOptions {
        time_samples: nt,
        ..PeriodicLcpOptions::default()
    };
    PeriodicLcp::new(&rod.model, rod.omega(), options).unwrap()
}

fn minimum(v: &[f64]) -> f64 {
    v.iter().cloned().fold(f64::INFINITY, f64::min)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn lcp_against_time_samples() {
    for mass in [MassModel::Modified, MassModel::Consistent] {
        for nt in [256usize, 1024] {
            let lcp = periodic_lcp(&rod(mass, false), nt);
            let (lo, hi) = lcp.symmetric_part_spectrum();
            let lemke = lcp
                .solve_with_lemke(&mut Lemke::new(lcp.dim()), &LemkeOptions::default())
                .unwrap();
            println!(
                "undamped, {mass:?} mass, Nt = {nt}: eig((A + A^T)/2) in [{lo:.4e}, {hi:.4e}]; \
                 Lemke {:?} after {} pivots",
                lemke.termination, lemke.pivots
            );
        }
    }
    for mass in [
        MassModel::Modified,
        MassModel::Consistent,
        MassModel::Lumped,
    ] {
        let rod = rod(mass, true);
        for nt in [128usize, 256, 512, 1024, 2048] {
            let start = std::time::Instant::now();
            let lcp = periodic_lcp(&rod, nt);
            let build = start.elapsed().as_secs_f64();
            let (lo, hi) = lcp.symmetric_part_spectrum();
            let generous = LemkeOptions {
                max_pivots: Some(100 * lcp.dim()),
                ..LemkeOptions::default()
            };
            let start = std::time::Instant::now();
            let lemke = lcp
                .solve_with_lemke(&mut Lemke::new(lcp.dim()), &generous)
                .unwrap();
            let lemke_time = start.elapsed().as_secs_f64();
            let start = std::time::Instant::now();
            let mut cold = vec![0.0; lcp.dim()];
            let mut solver = ActiveSetSolver::new()
                .with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)
                .unwrap();
            let cold_report = polyalgorithm::solve(
                &mut lcp.min_map(),
                &mut solver,
                &mut cold,
                &PolyalgorithmOptions::default(),
            )
            .unwrap();
            let cold_time = start.elapsed().as_secs_f64();
            let start = std::time::Instant::now();
            let sequenced =
                solve_min_map_sequenced(&rod.model, rod.omega(), &lcp, &SolveOptions::default())
                    .unwrap();
            let sequenced_time = start.elapsed().as_secs_f64();
            let tip = |z: &[f64]| minimum(&lcp.contact_displacements(z).unwrap()[0]);
            println!(
                "{mass:?} mass, Nt = {nt}: build {build:.3} s, eig((A + A^T)/2) in [{lo:.4e}, {hi:.4e}] \
                 | Lemke {:?}, {} pivots, error {:.1e}, {lemke_time:.3} s, tip min {:.10} \
                 | SSN from zero {:?}, {} iterations, {cold_time:.3} s \
                 | SSN sequenced converged {}, {} levels, {sequenced_time:.3} s, tip min {:.10} \
                 | |z_Lemke - z_sequenced| {:.1e}, |z_zero - z_sequenced| {:.1e}",
                lemke.termination,
                lemke.pivots,
                lemke.complementarity_error,
                tip(&lemke.z),
                cold_report.termination,
                cold_report.iterations,
                sequenced.converged(),
                sequenced.levels.len(),
                tip(&sequenced.z),
                max_abs_diff(&lemke.z, &sequenced.z),
                max_abs_diff(&cold, &sequenced.z)
            );
        }
    }
}

fn main() {
    lemke_at_2048();
    println!();
    lcp_against_time_samples();
}
