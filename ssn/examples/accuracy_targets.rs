//! The accuracy-targets table (module `ssn::accuracy_targets`): for each case, method and
//! target, what the discretisation search chose, its true error against the converged
//! reference, the estimate, and its cost against the cheapest setting that meets the target.
//!
//! `cargo run --release -p ssn --example accuracy_targets [-- METHOD ...]` prints the rows as
//! they are computed (every method without arguments).

use ssn::accuracy_targets::{
    reference, scan, target_cases, target_row, target_table, targets_of, METHODS,
};
use ssn::scene::Method;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let methods: Vec<Method> = std::env::args()
        .skip(1)
        .map(|a| {
            METHODS
                .into_iter()
                .find(|m| m.name() == a)
                .ok_or_else(|| format!("unknown method {a:?}"))
        })
        .collect::<Result<_, _>>()?;
    let methods = if methods.is_empty() {
        METHODS.to_vec()
    } else {
        methods
    };
    println!("{}", ssn::tables::machine_note());
    for case in target_cases() {
        let rod = semismooth_contact::rod::build_rod(&case.spec)?;
        let reference = reference(&rod)?;
        println!(
            "{}: reference uncertainty {:.1e}",
            case.name, reference.uncertainty
        );
        for &method in &methods {
            let targets = targets_of(method);
            let scanned = scan(&rod, method, &reference, targets[targets.len() - 1])?;
            for s in &scanned {
                println!(
                    "  {} level {} error {:.2e} {:.2} ms",
                    method.name(),
                    s.level,
                    s.error,
                    1e3 * s.seconds
                );
            }
            for &target in targets {
                let row = target_row(&rod, method, target, &reference, &scanned)?;
                print!(
                    "{}",
                    target_table(case.name, &[row])
                        .markdown()
                        .lines()
                        .nth(2)
                        .map_or(String::new(), |l| format!("{l}\n"))
                );
            }
        }
    }
    Ok(())
}
