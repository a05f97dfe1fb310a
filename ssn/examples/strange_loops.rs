//! The paper's "strange loops": SSN-HB enforces the contact only on the Fourier projection
//! (the Galerkin sense), so at small gaps the reconstructed tip passes the obstacle between
//! the AFT samples and the frequency response can turn back and forth where the pointwise
//! problem has a single response.
//!
//! For gaps 0.01 to 0.1 (the paper's rod: 20 elements, p0 = 0.04, zeta = 0.01, with the
//! modified mass so that the pointwise problem is well posed) and H = 5 (the paper's) and
//! H = 20, the example sweeps `[0.5, 2] omega_1` and lists the branch's turning points
//! (reversals of the frequency by at least 2e-3 omega_1) and the largest pointwise
//! penetration `max_t (u_tip(t) - g)` along it. Between each pair of neighbouring turning
//! points the branch crosses the midpoint frequency `w*` (at least) three times; there the
//! table compares the harmonic-balance amplitudes at the crossings (interpolated between
//! branch points), the penetration of the branch points in that interval, and the answer of
//! the periodic LCP (contact exact at every time node, 512 nodes per period, mesh-sequenced
//! Newton on the min map from zero, Lemke's algorithm where that does not converge) at
//! `w*`: its amplitude, its largest penetration and its relative distance to the nearest
//! HB amplitude.
//!
//! A pair of turning points that the LCP does not reproduce (one LCP response near only one
//! of the HB crossings, HB penetrating by a sizeable fraction of the gap) is a loop of the
//! Galerkin contact, not of the rod.
//!
//! `cargo run --release --example strange_loops` (about a minute on 2 cores).

use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::solve::solve;
use semismooth_contact::sweep::frequency_response;
use ssn::figures::fig2_rod;
use ssn::scene::{Method, SolverSettings, SweepSettings};

const GAPS: [f64; 7] = [0.01, 0.015, 0.02, 0.03, 0.05, 0.075, 0.1];
const HARMONICS: [usize; 2] = [5, 20];
/// LCP time nodes per period.
const LCP_NODES: usize = 512;

/// The largest finite value of `values`, at least 0 (undecided points carry NaN).
fn largest_finite(values: &[f64]) -> f64 {
    values
        .iter()
        .copied()
        .filter(|p| p.is_finite())
        .fold(0.0f64, f64::max)
}

fn main() {
    println!(
        "Strange loops: SSN-HB frequency responses of the rod (modified mass, p0 = 0.04) at \
         small gaps against the periodic LCP ({LCP_NODES} nodes)\n"
    );
    println!(
        "{:>3} {:>6} {:>6} {:>7} {:>9} {:>10}  turning points (omega/omega_1)",
        "H", "gap", "points", "corners", "max pen", "pen / gap"
    );
    let mut intervals = Vec::new();
    for h in HARMONICS {
        for gap in GAPS {
            let spec = RodSpec {
                mass: MassModel::Modified,
                ..fig2_rod(Some(gap))
            };
            let rod = build_rod(&spec).expect("rod");
            let settings = SolverSettings::with_harmonics(h);
            let r = frequency_response(&rod, &settings, &SweepSettings::new(0.5, 2.0), None)
                .expect("sweep");
            let w1 = rod.omega_1;
            let penetration = r.column(|p| p.stability.max_penetration);
            let max_pen = largest_finite(&penetration);
            let folds: Vec<String> = r.folds.iter().map(|w| format!("{:.4}", w / w1)).collect();
            println!(
                "{h:>3} {gap:>6} {:>6} {:>7} {max_pen:>9.2e} {:>10.3}  {}{}",
                r.points.len(),
                r.corner_folds.len(),
                max_pen / gap,
                if folds.is_empty() {
                    "none".to_string()
                } else {
                    folds.join(", ")
                },
                if r.converged() {
                    ""
                } else {
                    " (stopped early)"
                }
            );
            for k in 1..r.folds.len() {
                let (a, b) = (r.fold_indices[k - 1], r.fold_indices[k]);
                let target = 0.5 * (r.folds[k - 1] + r.folds[k]);
                // HB amplitudes where the branch crosses w* (linear interpolation).
                let crossings: Vec<f64> = r
                    .points
                    .windows(2)
                    .filter(|p| (p[0].omega - target) * (p[1].omega - target) <= 0.0)
                    .map(|p| {
                        let (w0, w1p) = (p[0].omega, p[1].omega);
                        let t = if w1p != w0 {
                            (target - w0) / (w1p - w0)
                        } else {
                            0.0
                        };
                        p[0].amplitude + t * (p[1].amplitude - p[0].amplitude)
                    })
                    .collect();
                let between = largest_finite(&penetration[a.min(b)..=a.max(b)]);
                intervals.push((h, gap, target / w1, crossings, between, rod.clone()));
            }
        }
    }
    println!(
        "\nBetween neighbouring turning points: HB amplitudes at the midpoint frequency w*, the \
         largest HB penetration there, and the periodic LCP at w*\n"
    );
    println!(
        "{:>3} {:>6} {:>9} {:>10} {:>30} {:>10}  LCP amplitude, penetration, nearest HB",
        "H", "gap", "w*/w_1", "HB pen/g", "HB amplitudes at w*", "crossings"
    );
    for (h, gap, ratio, crossings, between, rod) in intervals {
        let omega = ratio * rod.omega_1;
        let lcp_settings = SolverSettings {
            method: Method::LcpSsn,
            time_samples: LCP_NODES,
            ..SolverSettings::with_harmonics(h)
        };
        // Newton on the min map first; Lemke's pivoting where it does not converge.
        let lcp = match solve(&rod.structure, omega, &lcp_settings, None) {
            Ok(s) if s.converged() => Ok(s),
            _ => {
                let lemke = SolverSettings {
                    method: Method::LcpLemke,
                    ..lcp_settings.clone()
                };
                solve(&rod.structure, omega, &lemke, None)
            }
        };
        let amplitudes: Vec<String> = crossings.iter().map(|a| format!("{a:.4}")).collect();
        let lcp_text = match lcp {
            Ok(s) if s.converged() => {
                let amplitude = s.stats.max.abs().max(s.stats.min.abs());
                let nearest = crossings
                    .iter()
                    .map(|a| (a - amplitude).abs() / amplitude)
                    .fold(f64::INFINITY, f64::min);
                format!(
                    "{amplitude:.4}, {:.1e}, {:.1} %",
                    s.stats.max_penetration,
                    100.0 * nearest
                )
            }
            Ok(s) => format!("not converged: {}", s.termination),
            Err(e) => format!("error: {e}"),
        };
        println!(
            "{h:>3} {gap:>6} {ratio:>9.4} {:>10.3} {:>30} {:>10}  {lcp_text}",
            between / gap,
            amplitudes.join(" "),
            crossings.len()
        );
    }
}
