//! Cost of one SSN-HB solve (H = 20, from zero, structured solver, single-threaded) against
//! the number of rod elements: the modified-mass canonical rod refined to 1,000 ... 100,000
//! elements with the contact at the tip. Prints a table (elements, unknowns, iterations,
//! seconds, seconds per iteration) and the exponent `p` of `seconds ~ elements^p` fitted by
//! least squares on log-log axes.
//!
//! The complementarity constant is the rod's static tip stiffness `c = EA / L` (mesh
//! independent). The local stiffness `K[tip, tip] = 2 n EA / L` grows with the element
//! count, and from zero Newton then cycles between active sets (no convergence in 200
//! iterations from 100 elements up, measured).
//!
//! Newton tolerance: 1e-10 on the residual 2-norm at the canonical 20 elements, scaled by
//! `n / 20` like `|K|`: the residual's round-off floor grows with `|K| ~ n` (measured: an
//! absolute 1e-10 stalls at 4e-10 with 30,000 elements after the iterate converged in 13
//! iterations; the last Newton step jumps from 1e-4 to that floor, so the iteration count
//! does not depend on where in between the tolerance lies).
//!
//! `cargo run --release --example scaling [MAX_ELEMENTS]` (default 100000)

use std::time::Instant;

use semismooth::polyalgorithm::SmoothingOf;
use semismooth::Residual;

use semismooth_contact::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodSpec};
use semismooth_contact::settings::{default_hb_time_samples, SolverSettings};
use semismooth_contact::solve::newton_options;

const H: usize = 20;

/// Slope of the least-squares line through `(ln x, ln y)`.
fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|(x, y)| (x.ln(), y.ln())).unzip();
    let mx = lx.iter().sum::<f64>() / n;
    let my = ly.iter().sum::<f64>() / n;
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    faer::set_global_parallelism(faer::Par::Seq);
    let max: usize = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 100_000,
    };
    println!(
        "{:>9} {:>10} {:>6} {:>11} {:>13}",
        "elements", "unknowns", "iter", "seconds", "s/iteration"
    );
    let mut points = Vec::new();
    for n in [1000, 3000, 10_000, 30_000, 100_000] {
        if n > max {
            break;
        }
        let spec = RodSpec {
            mass: MassModel::Modified,
            elements: n,
            contacts: vec![RodContact { node: n, gap: 0.5 }],
            ..RodSpec::canonical()
        };
        let hb = HbOptions {
            harmonics: H,
            time_samples: Some(default_hb_time_samples(H)),
            c: Some(spec.axial_stiffness / spec.length),
        };
        let rod = build_rod(&spec)?;
        let options = newton_options(&SolverSettings {
            tolerance: 1e-10 * n as f64 / 20.0,
            ..SolverSettings::with_harmonics(H)
        });
        // Median of 3 solves below 10,000 elements, one above; each from zero, problem and
        // solver built inside the timed region.
        let repeats = if n < 10_000 { 3 } else { 1 };
        let mut times = Vec::new();
        let mut iterations = 0;
        let mut unknowns = 0;
        for _ in 0..repeats {
            let start = Instant::now();
            let mut problem = SsnHb::new(&rod.model, rod.omega(), &hb)?;
            let mut x = vec![0.0; problem.dim()];
            let mut solver = StructuredHbSolver::new();
            let report =
                options.solve(&mut problem, &mut solver, &mut x, Some(SmoothingOf::new()))?;
            times.push(start.elapsed().as_secs_f64());
            if !report.converged() {
                return Err(format!(
                    "{n} elements: {:?}, residual norms {:?}",
                    report.termination, report.residual_norms
                )
                .into());
            }
            iterations = report.iterations;
            unknowns = problem.dim();
        }
        times.sort_by(f64::total_cmp);
        let seconds = times[times.len() / 2];
        println!(
            "{n:>9} {unknowns:>10} {iterations:>6} {seconds:>11.4} {:>13.3e}",
            seconds / iterations.max(1) as f64
        );
        points.push((n as f64, seconds));
    }
    if points.len() >= 2 {
        println!(
            "fitted exponent (seconds ~ elements^p, log-log least squares): p = {:.3}",
            log_log_slope(&points)
        );
    }
    Ok(())
}
