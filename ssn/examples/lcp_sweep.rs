//! Frequency-response curves of the canonical rod (20 elements, zeta = 0.01, modified mass,
//! gap 0.5, p0 = 0.04) over omega/omega_1 in [0.5, 2]: SSN-HB (H = 20) against the
//! periodic LCP continued in (w, z) (method lcp-ssn, Nt = 128, 256, 512), one run, with
//! wall times, folds and peaks.
//!
//! `cargo run --release --example lcp_sweep [NT ...]`

use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::SolverSettings;
use semismooth_contact::sweep::frequency_response;
use ssn::scene::{Method, SweepSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let sizes = if sizes.is_empty() {
        vec![128, 256, 512]
    } else {
        sizes
    };
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })?;
    let sweep = SweepSettings {
        max_points: 5000,
        ..SweepSettings::new(0.5, 2.0)
    };
    println!(
        "{:<16} {:>7} {:>9} {:>6} {:>9} {:>12} {:>10}  folds (count, lowest, highest omega/omega_1)",
        "method", "points", "converged", "restarts", "seconds", "peak", "at"
    );
    let hb: Vec<usize> = std::env::var("HB").ok().map_or(vec![20, 40], |v| {
        v.split(',').map(|h| h.parse().unwrap()).collect()
    });
    let mut runs: Vec<(Method, usize)> = hb.iter().map(|&h| (Method::SsnHb, h)).collect();
    runs.extend(sizes.iter().map(|&nt| (Method::LcpSsn, nt)));
    for (method, size) in runs {
        let mut settings =
            SolverSettings::with_harmonics(if method == Method::SsnHb { size } else { 20 });
        settings.method = method;
        if method == Method::LcpSsn {
            settings.time_samples = size;
        }
        let r = frequency_response(&rod, &settings, &sweep, None)?;
        let (ip, peak) = r.peak().unwrap_or((0, f64::NAN));
        let label = match method {
            Method::SsnHb => format!("ssn-hb H={size}"),
            _ => format!("lcp-ssn Nt={size}"),
        };
        println!(
            "{label:<16} {:>7} {:>9} {:>6} {:>9.3} {:>12.7} {:>10.6}  {:?}",
            r.points.len(),
            r.converged(),
            r.restarts,
            r.solve_seconds,
            peak,
            r.points[ip].omega / rod.omega_1,
            (
                r.folds.len(),
                r.folds.iter().copied().fold(f64::INFINITY, f64::min) / rod.omega_1,
                r.folds.iter().copied().fold(f64::NEG_INFINITY, f64::max) / rod.omega_1
            )
        );
        if !r.converged() {
            println!("    {}", r.termination);
        }
        println!(
            "    corrector iterations {}, rejected steps {}, factorizations {}",
            r.continuation.corrector_iterations,
            r.continuation.rejected_steps,
            r.counters.factorizations
        );
    }
    Ok(())
}
