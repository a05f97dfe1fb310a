//! The frequency response of a two-dof chain with a stop on its free mass (a contact on a
//! dof that carries mass), swept over `[0.5, 3] omega_1` at several harmonic counts: the
//! folds of the branch, the zigzags of the truncated balance told apart from them, and
//! the stability along the branch with its bifurcations (the harmonic-balance orbit
//! rebounds off the stop, so the verdict is that of an impact with the orbit's own
//! restitution, close to 1; module `stability`).
//!
//! ```text
//! cargo run --release -p semismooth-contact --example two_dof_chain [gap zeta f0 f1]
//! ```
//!
//! Arguments (optional): the gap, the damping ratio at the first mode and the forces on
//! masses 0 and 1 (default `0.5 0.02 0 0.1`). `HS=10,20,40` chooses the harmonic counts;
//! `DUMP=1` prints every point (frequency, tip extremes, Newton iterations, verdict,
//! largest multiplier modulus).
mod args;
#[path = "../tests/common/chain.rs"]
mod chain;

use args::positional;
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::frequency_response;

fn main() {
    let arg = |i: usize, d: f64| positional(i, d, "a number");
    let structure = chain::chain(arg(1, 0.5), arg(2, 0.02), [arg(3, 0.0), arg(4, 0.1)]);
    let omega_1 = structure.omega_1;
    let hs: Vec<usize> = std::env::var("HS")
        .map(|v| {
            v.split(',')
                .map(|x| x.parse().expect("an integer"))
                .collect()
        })
        .unwrap_or(vec![10, 20, 40]);
    println!("   H  points  converged  folds (omega_1)         zigzags  stable  unstable  undecided  solve s  stability s");
    for h in hs {
        let settings = SolverSettings::with_harmonics(h);
        let r = frequency_response(&structure, &settings, &SweepSettings::new(0.5, 3.0), None)
            .expect("valid settings");
        let count = |v: Option<bool>| r.stable().iter().filter(|s| **s == v).count();
        let folds: Vec<String> = r
            .folds
            .iter()
            .map(|w| format!("{:.4}", w / omega_1))
            .collect();
        println!(
            "{h:>4}  {:>6}  {:>9}  {:<22}  {:>7}  {:>6}  {:>8}  {:>9}  {:>7.2}  {:>11.2}",
            r.points.len(),
            r.converged(),
            folds.join(", "),
            r.corner_folds.len(),
            count(Some(true)),
            count(Some(false)),
            count(None),
            r.solve_seconds,
            r.stability_seconds
        );
        for e in &r.events {
            println!(
                "      {} at {:.4} omega_1 (point {})",
                e.kind.name(),
                e.omega / omega_1,
                e.index
            );
        }
        if std::env::var("DUMP").is_ok() {
            for i in 0..r.points.len() {
                println!(
                    "{i} {:.6} {:.6} {:.6} it {} stable {:?} mu {:?}",
                    r.points[i].omega / omega_1,
                    r.points[i].observed_max,
                    r.points[i].observed_min,
                    r.points[i].iterations,
                    r.points[i].stability.stable,
                    r.points[i].stability.floquet_max_abs,
                );
            }
        }
    }
}
