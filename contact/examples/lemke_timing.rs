//! Lemke's algorithm at n = 2048: wall and CPU time, pivots and complementarity error on
//! the periodic LCP of the canonical rod (both mass models), a circulant stand-in and a
//! random symmetric positive definite LCP (nothing asserted; the tests check correctness).
//!
//! `cargo run --release -p semismooth-contact --example lemke_timing`

use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use semismooth::lemke::{Lemke, LemkeOptions};
use semismooth_contact::lcp::{PeriodicLcp, PeriodicLcpOptions};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};

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

fn main() {
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
        let spec = RodSpec {
            mass,
            ..RodSpec::canonical()
        };
        let rod = build_rod(&spec).unwrap();
        let options = PeriodicLcpOptions {
            time_samples: n,
            ..PeriodicLcpOptions::default()
        };
        let lcp = PeriodicLcp::new(&rod.model, rod.omega(), options).unwrap();
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
