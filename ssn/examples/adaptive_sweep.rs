//! Harmonics chosen point by point along a branch for an accuracy target, against the
//! fixed harmonics that reach the same worst error ([`ssn::adaptive_sweeps`]): every
//! point's error against SSN-HB at H = 320 at its frequency, its estimate beside it, and
//! the cost of both sweeps measured in the same run.
//!
//! ```sh
//! cargo run --release -p ssn --example adaptive_sweep                  # the docs' table
//! cargo run --release -p ssn --example adaptive_sweep -- 1e-4 --points # one target, per point
//! cargo run --release -p ssn --example adaptive_sweep -- 1e-3 --strong  # p0 = 0.2
//! ```
//!
//! The docs' block (docs/sweeps.md) is written by
//! `cargo run --release -p ssn --example docs_tables -- --write adaptive-sweeps`.

use ssn::adaptive_sweeps::{compare_adaptive, paper_rod, strongly_forced_rod, study};
use ssn::tables;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    faer::set_global_parallelism(faer::Par::Seq);
    let say = |line: &str| eprintln!("  {line}");
    let points = std::env::args().any(|a| a == "--points");
    let strong = std::env::args().any(|a| a == "--strong");
    let target: Option<f64> = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with("--"))
        .map(|a| a.parse())
        .transpose()?;
    let rows = match target {
        Some(target) => {
            let (label, rod) = if strong {
                ("strongly forced rod", strongly_forced_rod()?)
            } else {
                ("paper's rod", paper_rod()?)
            };
            vec![(
                label.to_string(),
                compare_adaptive(&rod, target, Some(&say))?,
            )]
        }
        None => study(Some(&say))?,
    };
    println!("{}\n", tables::machine_note());
    print!("{}", tables::adaptive_sweeps(&rows).markdown());
    if points {
        for (label, c) in &rows {
            println!(
                "\n{label}, target {:e} ({}): point, omega/omega_1, H, error, estimate",
                c.target, c.termination
            );
            for (i, (e, s)) in c.errors.iter().zip(&c.estimates).enumerate() {
                println!(
                    "{i:4} {:9.5} {:4} {e:10.2e} {s:10.2e}",
                    c.omega_ratio[i], c.point_harmonics[i]
                );
            }
        }
    }
    Ok(())
}
