//! The friction points' numbers in the tables: `ssn sweep --csv` and the study table carry
//! each friction point's stick fraction, largest force, largest slip velocity and largest
//! slip limit, the very values of the JSON documents (one list of names and values,
//! `FrictionSummary::named`).

#[path = "common/process.rs"]
mod process;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use process::{assert_success, json_success, ssn};
use semismooth_contact::contacts::FrictionSummary;
use serde_json::Value;

fn damper() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/friction_damper.toml")
}

/// A CSV file's columns by name (empty cells as NaN).
fn csv_columns(path: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).expect("the CSV file");
    let mut lines = text.lines();
    let names: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let mut columns: HashMap<String, Vec<f64>> = HashMap::new();
    for line in lines {
        for (name, cell) in names.iter().zip(line.split(',')) {
            let value = cell.parse().unwrap_or(f64::NAN);
            columns.entry(name.to_string()).or_default().push(value);
        }
    }
    columns
}

/// Both printed with the shortest round-trip text of the same `f64`: equal exactly.
fn assert_same(table: f64, json: &Value, what: &str) {
    assert_eq!(Some(table), json.as_f64(), "{what}");
}

/// The damper's sweep CSV has `friction0_<name>` for each name of the friction summary,
/// equal at every point to that point's `friction` numbers of `ssn sweep --json`.
#[test]
fn sweep_csv_carries_the_friction_points_numbers_of_the_json() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("sweep.csv");
    let scene = damper();
    let args = ["sweep", scene.to_str().unwrap(), "--quiet"];
    let doc = json_success(&ssn(&[
        &args[..],
        &["--json", "--csv", csv.to_str().unwrap()],
    ]
    .concat()));
    let columns = csv_columns(&csv);
    let points = doc["friction"].as_array().expect("per-point friction");
    assert!(points.len() > 10, "{} points", points.len());
    for name in FrictionSummary::NAMES {
        let column = &columns[&format!("friction0_{name}")];
        assert_eq!(column.len(), points.len(), "{name}: rows");
        for (value, point) in column.iter().zip(points) {
            assert_same(*value, &point[0][name], name);
        }
    }
}

/// The damper has friction points and no unilateral contact: its sweep CSV carries the
/// friction columns and none of the unilateral contacts' (`contact_force_mean`,
/// `max_penetration`, `contact{k}_...`), which would be zeros of a law it does not have.
#[test]
fn damper_sweep_csv_has_the_columns_of_its_friction_points_and_none_of_normal_contact() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("sweep.csv");
    let scene = damper();
    let args = ["sweep", scene.to_str().unwrap(), "--quiet", "--csv"];
    json_success(&ssn(
        &[&args[..], &[csv.to_str().unwrap(), "--json"]].concat()
    ));
    let columns = csv_columns(&csv);
    for name in FrictionSummary::NAMES {
        assert!(columns.contains_key(&format!("friction0_{name}")), "{name}");
    }
    let normal: Vec<&String> = (columns.keys())
        .filter(|k| {
            *k == "contact_force_mean" || *k == "max_penetration" || k.starts_with("contact")
        })
        .collect();
    assert!(
        normal.is_empty(),
        "columns of a law the scene lacks: {normal:?}"
    );
}

/// A study of the damper's solve over two normal loads: its table has
/// `friction0_<name>` equal to each case's `ssn solve --json` friction numbers.
#[test]
fn study_table_carries_the_friction_points_numbers_of_each_solve() {
    let dir = tempfile::tempdir().unwrap();
    let study = dir.path().join("study.toml");
    let loads = [0.002, 0.004];
    std::fs::write(
        &study,
        format!("run = \"solve\"\n[grid]\n\"friction.point.0.normal_load\" = {loads:?}\n"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let scene = damper();
    let (scene, study, out) = (
        scene.to_str().unwrap(),
        study.to_str().unwrap(),
        out.clone(),
    );
    let o = ssn(&[
        "study",
        scene,
        study,
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_success(&o);
    let columns = csv_columns(&out.join("results.csv"));
    for (row, load) in loads.iter().enumerate() {
        let set = format!("friction.point.0.normal_load={load}");
        let doc = json_success(&ssn(&["solve", scene, "--json", "--quiet", "--set", &set]));
        let friction = &doc["friction"][0];
        for name in FrictionSummary::NAMES {
            let value = columns[&format!("friction0_{name}")][row];
            assert_same(value, &friction[name], name);
        }
    }
}
