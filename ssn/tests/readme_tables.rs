//! README.md's measured tables hold what the code computes: the cheap tables are recomputed
//! here (`ssn::tables`, the functions `examples/readme_tables.rs` prints)
//! and every deterministic cell (iteration counts, points, folds, errors rounded as printed)
//! must be in README.md exactly; wall-time columns are not compared. A README number that
//! drifts from the code fails here: regenerate the table with
//! `cargo run --release --example readme_tables -- SECTION` and paste it.

use semismooth_contact::from_zero::{hard_cases, public_grid};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use ssn::scene::{GlobalizationChoice, SolverSettings};
use ssn::study::accuracy_cost;
use ssn::tables::{self, Table};

fn readme() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md"))
        .expect("README.md is readable")
}

/// Every row of `table` is in README.md's table of the same header with the same
/// deterministic cells; with `complete`, README's table has no other rows either.
fn assert_in_readme(section: &str, table: &Table, complete: bool) {
    let mut differences = table.differences_in(&readme());
    let rows = table.rows_in(&readme()).unwrap_or_default();
    if complete && rows.len() != table.rows.len() {
        differences.push(format!(
            "README has {} rows, the code {}",
            rows.len(),
            table.rows.len()
        ));
    }
    assert!(
        differences.is_empty(),
        "README.md differs from the code (`cargo run --release --example readme_tables -- \
         {section}` prints the table):\n{}\n\nthe code's table:\n{}",
        differences.join("\n"),
        table.markdown()
    );
}

#[test]
fn method_comparison_tables_are_the_codes() {
    for mass in [MassModel::Modified, MassModel::Consistent] {
        let (table, _) = tables::method_comparison(mass).unwrap();
        assert_in_readme("methods", &table, true);
    }
}

#[test]
fn sweep_table_is_the_codes_for_the_sweeps_under_a_second() {
    let cheap: Vec<_> = tables::sweep_cases()
        .into_iter()
        .filter(|c| !c.slow)
        .collect();
    assert!(cheap.len() >= 5);
    let table = tables::sweeps(&cheap).unwrap();
    assert_in_readme("sweeps", &table, false);
    // The slow rows are there too, one per sweep.
    let rows = table.rows_in(&readme()).unwrap();
    assert_eq!(rows.len(), tables::sweep_cases().len(), "{rows:?}");
}

#[test]
fn from_zero_grid_table_is_the_codes() {
    let groups = public_grid(&[0.1, 0.2, 0.4]).unwrap();
    let run = |g: GlobalizationChoice| -> Vec<tables::GroupSummary> {
        groups
            .iter()
            .map(|(name, cases)| tables::solve_group(name, cases, g))
            .collect()
    };
    let table = tables::from_zero_grid(
        &run(GlobalizationChoice::Auto),
        &run(GlobalizationChoice::Hybrid),
    );
    assert_in_readme("from-zero", &table, true);
}

#[test]
fn performance_counts_are_the_codes() {
    assert_in_readme("performance", &tables::performance().unwrap(), true);
}

/// Which setting is cheapest depends on the times, so the cells are not compared as text:
/// each setting the README names must be one the study ran, converged, and reach the
/// accuracy of its column; and the README lists every method of the study.
#[test]
fn cheapest_settings_in_the_readme_reach_their_accuracy() {
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .unwrap();
    let settings = SolverSettings::with_harmonics(20);
    let study = accuracy_cost(&rod.structure, rod.omega(), &settings, None).unwrap();
    let table = tables::cheapest_settings(&study);
    let rows = table
        .rows_in(&readme())
        .expect("README has the cheapest-settings table");
    assert_eq!(rows.len(), table.rows.len(), "{rows:?}");
    for (row, ours) in rows.iter().zip(&table.rows) {
        assert_eq!(row[0], ours[0], "methods in the study's order");
        for (column, accuracy) in [(1, 1e-3), (2, 1e-4)] {
            let setting = row[column]
                .rsplit_once(", ")
                .map_or(row[column].as_str(), |(s, _)| s);
            let entry = study
                .entries
                .iter()
                .find(|e| e.method.name() == row[0] && e.setting == setting)
                .unwrap_or_else(|| panic!("{}: no setting {setting:?} in the study", row[0]));
            println!(
                "{} {setting}: error {:.2e} for {accuracy:.0e}",
                row[0], entry.tip_min_error
            );
            assert!(
                entry.converged && entry.tip_min_error <= accuracy,
                "{} {setting}: error {:e} > {accuracy:e}",
                row[0],
                entry.tip_min_error
            );
        }
    }
}

/// The hard cases that take under a second (not the 1,000-element rods with 50 and 100
/// contacts, nor the LCP over its time grids).
#[test]
fn hard_cases_table_is_the_codes_for_the_cases_under_a_second() {
    let slow = ["50 contacts", "100 contacts", "lcp-ssn"];
    let groups: Vec<tables::GroupSummary> = hard_cases()
        .unwrap()
        .iter()
        .filter(|(name, _)| !slow.iter().any(|s| name.contains(s)))
        .map(|(name, cases)| tables::solve_group(name, cases, GlobalizationChoice::Auto))
        .collect();
    assert_eq!(groups.len(), 5);
    let table = tables::from_zero_hard(&groups);
    assert_in_readme("hard", &table, false);
    let rows = table.rows_in(&readme()).unwrap();
    assert_eq!(rows.len(), hard_cases().unwrap().len(), "{rows:?}");
}
