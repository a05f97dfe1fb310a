//! The measured tables of `docs/` hold what the code computes: the cheap tables are
//! recomputed here (`ssn::tables`, the functions `examples/docs_tables.rs` prints) and
//! every deterministic cell (iteration counts, points, folds, errors rounded as printed)
//! must be in the section's docs file exactly, inside its generated block; wall-time
//! columns are not compared. A documented number that drifts from the code fails here:
//! regenerate the block with
//! `cargo run --release -p ssn --example docs_tables -- --write SECTION`.

use semismooth_contact::from_zero::{hard_cases, public_grid};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use ssn::accuracy_cost::accuracy_cost;
use ssn::scene::{GlobalizationChoice, SolverSettings};
use ssn::tables::{self, Table};

/// The generated block of `section` in its docs file (the lines between its markers).
fn block(section: &str) -> String {
    let file = tables::section(section)
        .unwrap_or_else(|| panic!("no section {section:?}"))
        .file;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../").to_string() + file;
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let (start, end) = (tables::block_start(section), tables::block_end(section));
    let open = text
        .find(&start)
        .unwrap_or_else(|| panic!("{file}: no line {start:?}"));
    let close = text[open..]
        .find(&end)
        .unwrap_or_else(|| panic!("{file}: no line {end:?} after {start:?}"));
    text[open..open + close].to_string()
}

/// Every row of `table` is in the section's block, in its table of the same header, with
/// the same deterministic cells; with `complete`, that table has no other rows either.
fn assert_in_docs(section: &str, table: &Table, complete: bool) {
    let text = block(section);
    let mut differences = table.differences_in(&text);
    let rows = table.rows_in(&text).unwrap_or_default();
    if complete && rows.len() != table.rows.len() {
        differences.push(format!(
            "the docs have {} rows, the code {}",
            rows.len(),
            table.rows.len()
        ));
    }
    assert!(
        differences.is_empty(),
        "{} differs from the code (`cargo run --release -p ssn --example docs_tables -- \
         --write {section}` rewrites it):\n{}\n\nthe code's table:\n{}",
        tables::section(section).unwrap().file,
        differences.join("\n"),
        table.markdown()
    );
}

#[test]
fn method_comparison_tables_are_the_codes() {
    for mass in [MassModel::Modified, MassModel::Consistent] {
        let (table, _) = tables::method_comparison(mass).unwrap();
        assert_in_docs("methods", &table, true);
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
    assert_in_docs("sweeps", &table, false);
    // The slow rows are there too, one per sweep.
    let rows = table.rows_in(&block("sweeps")).unwrap();
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
    assert_in_docs("from-zero", &table, true);
}

#[test]
fn performance_counts_are_the_codes() {
    assert_in_docs("performance", &tables::performance().unwrap(), true);
}

/// Which setting is cheapest depends on the times, so the cells are not compared as text:
/// each setting the docs name must be one the study ran, converged, and reach the accuracy
/// of its column; and the docs list every method of the study.
#[test]
fn cheapest_settings_in_the_docs_reach_their_accuracy() {
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .unwrap();
    let settings = SolverSettings::with_harmonics(20);
    let study = accuracy_cost(&rod.structure, rod.omega(), &settings, None).unwrap();
    let table = tables::cheapest_settings(&study);
    let rows = table
        .rows_in(&block("accuracy"))
        .expect("the docs have the cheapest-settings table");
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
    assert_in_docs("hard", &table, false);
    let rows = table.rows_in(&block("hard")).unwrap();
    assert_eq!(rows.len(), hard_cases().unwrap().len(), "{rows:?}");
}

/// The check itself fails when a deterministic cell drifts: one iteration count changed
/// in a copy of the method comparison's block is reported.
#[test]
fn a_drifted_cell_is_reported() {
    let (table, _) = tables::method_comparison(MassModel::Modified).unwrap();
    let text = block("methods");
    assert!(table.differences_in(&text).is_empty());
    let row = &table.rows[1];
    let line = format!("| {} |", row.join(" | "));
    let mut cells = row.clone();
    cells[1] = format!("{}0", cells[1]);
    let drifted = text.replacen(
        &line[..line.find(" | ").unwrap() + 3 + row[1].len()],
        &format!("| {} | {}", cells[0], cells[1]),
        1,
    );
    assert_ne!(drifted, text, "the row {line:?} is in the block");
    let differences = table.differences_in(&drifted);
    assert_eq!(differences.len(), 1, "{differences:?}");
    assert!(differences[0].contains("iterations"), "{differences:?}");
}

#[test]
fn accuracy_target_rows_for_1e_3_on_the_paper_rod_are_the_codes_and_meet_it() {
    use ssn::accuracy_targets::{case_rows, target_cases, target_table};
    use ssn::scene::Method;
    let case = &target_cases()[0];
    let methods = [Method::SsnHb, Method::LcpSsn, Method::March];
    let (_, rows) = case_rows(case, &methods, &[1e-3]).unwrap();
    for r in &rows {
        // The chosen setting meets the target against the reference, and the estimate is
        // within a third and ten times the true error.
        assert!(r.met, "{r:?}");
        assert!(r.true_error <= r.target, "{r:?}");
        let ratio = r.ratio().unwrap();
        assert!((1.0 / 3.0..=10.0).contains(&ratio), "{r:?}");
    }
    assert_in_docs("accuracy-targets", &target_table(case.name, &rows), false);
}

#[test]
fn friction_tables_are_the_codes() {
    // Den Hartog's oscillator by H (SSN-HB against the closed form) and the damper curve
    // (the resonance peak of two blades against the damper's normal load): about 5 s.
    assert_in_docs(
        "friction",
        &ssn::friction_tables::den_hartog_convergence().unwrap(),
        true,
    );
    assert_in_docs(
        "friction",
        &ssn::friction_tables::damper_curve().unwrap(),
        true,
    );
}

#[test]
fn adaptive_sweep_row_for_1e_2_on_the_paper_rod_is_the_codes_and_meets_it() {
    use ssn::adaptive_sweeps::{compare_adaptive, paper_rod};
    let rod = paper_rod().unwrap();
    let comparison = compare_adaptive(&rod, 1e-2, None).unwrap();
    // Every point within the target against the branch at the reference's harmonics taken
    // up across it, and the estimate neither below a third nor above ten times the error.
    assert_eq!(comparison.met(), comparison.points, "{comparison:?}");
    assert!(comparison.worst_underestimate() <= 3.0, "{comparison:?}");
    assert!(comparison.worst_overestimate() <= 10.0, "{comparison:?}");
    let rows = vec![("paper's rod".to_string(), comparison)];
    assert_in_docs("adaptive-sweeps", &tables::adaptive_sweeps(&rows), false);
}
