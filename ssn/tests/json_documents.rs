//! The JSON documents of the program against the results they print.

mod common;

use semismooth_contact::rod::MassModel;
use semismooth_contact::settings::{Method, SweepSettings};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

/// The forced rod of fig. 2 (gap 0.5, load 0.04, consistent mass) swept by SSN-HB at
/// `H = 3` over 0.8-1.2 `omega_1`.
fn swept_rod() -> (semismooth_contact::rod::RodModel, FrequencyResponse) {
    let rod = common::fig2_rod_model(Some(0.5), 0.04, MassModel::Consistent);
    let r = frequency_response(
        &rod,
        &common::sweep_solver(Method::SsnHb, 3),
        &SweepSettings::new(0.8, 1.2),
        None,
    )
    .unwrap();
    (rod, r)
}

#[test]
fn sweep_json_has_the_documented_fields_one_entry_per_point() {
    let (_, r) = swept_rod();
    assert!(r.converged(), "{}", r.termination);
    let v = ssn::json::response_json(&r);
    for key in common::json_fields::SWEEP {
        assert!(v.get(key).is_some(), "{key}");
    }
    assert_eq!(v["points"].as_u64().unwrap() as usize, r.points.len());
    assert_eq!(v["omega"].as_array().unwrap().len(), r.points.len());
    assert_eq!(v["folds"].as_array().unwrap().len(), r.folds.len());
    assert_eq!(v["converged"].as_bool(), Some(true));
}

#[test]
fn sweep_and_solve_json_carry_omega_1_and_the_folds_in_its_units() {
    let (rod, r) = swept_rod();
    let v = ssn::json::response_json(&r);
    assert_eq!(v["omega_1"].as_f64(), Some(rod.omega_1));
    assert!(!r.folds.is_empty(), "the forced rod folds in this window");
    // (The corner folds may be none in this window: the folds are asserted above.)
    for (folds, ratios) in [
        ("folds", "fold_ratios"),
        ("corner_folds", "corner_fold_ratios"),
    ] {
        let (folds, ratios) = (v[folds].as_array().unwrap(), v[ratios].as_array().unwrap());
        assert_eq!(folds.len(), ratios.len());
        for (w, ratio) in folds.iter().zip(ratios) {
            // One division: the ratio times omega_1 is the fold to the last bit or two.
            let back = ratio.as_f64().unwrap() * rod.omega_1;
            assert!((back - w.as_f64().unwrap()).abs() <= 4.0 * f64::EPSILON * back.abs());
        }
    }
    let solution = semismooth_contact::solve::solve(
        &rod,
        rod.omega_1,
        &common::sweep_solver(Method::SsnHb, 3),
        None,
    )
    .unwrap();
    let doc = ssn::json::solution_json(std::path::Path::new("rod.toml"), &solution);
    assert_eq!(doc["omega_1"].as_f64(), Some(rod.omega_1));
    assert_eq!(doc["omega_ratio"].as_f64(), Some(1.0));
}

/// The bilinear oscillator `u'' + 0.04 u' + u = -20 (u - w) + cos(w t)`, its massless node
/// `w` against a stop at 0: a period doubling near `w = 2.43`.
fn bilinear_oscillator() -> semismooth_contact::model::Structure {
    use semismooth_contact::builder::sparse_matrix;
    use semismooth_contact::model::{ContactPoint, HarmonicLoad, StructuralModel, Structure};
    let sparse = |entries: &[(usize, usize, f64)]| sparse_matrix(2, entries).unwrap();
    Structure {
        model: StructuralModel {
            mass: sparse(&[(0, 0, 1.0)]),
            damping: Some(sparse(&[(0, 0, 0.04)])),
            stiffness: sparse(&[(0, 0, 21.0), (0, 1, -20.0), (1, 0, -20.0), (1, 1, 20.0)]),
            load: HarmonicLoad::cosine(vec![1.0, 0.0]),
            contacts: vec![ContactPoint::new(1, 0.0)],
            friction: Vec::new(),
            cyclic: None,
            frictional_contacts: Vec::new(),
        },
        omega_1: 1.0,
        observed_dof: 0,
    }
}

/// The sweep of [`bilinear_oscillator`] from 1.5 to 3.2 (H = 20, step 0.02), following
/// period-2 branches or not.
fn bilinear_sweep(period_two: bool) -> semismooth_contact::sweep::FrequencyResponse {
    let mut sweep = SweepSettings::new(1.5, 3.2);
    sweep.step = 0.02;
    sweep.period_two = period_two;
    frequency_response(
        &bilinear_oscillator(),
        &common::sweep_solver(Method::SsnHb, 20),
        &sweep,
        None,
    )
    .unwrap()
}

#[test]
fn sweep_json_carries_the_period_two_branch_with_period_multiple_two() {
    use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
    let r = bilinear_sweep(true);
    let Some(PeriodTwoOutcome::Followed(b)) = r.period_two.first() else {
        panic!("{:?}", r.period_two);
    };
    let v = ssn::json::response_json(&r);
    let doc = &v["period_two"][0];
    assert_eq!(doc["period_multiple"].as_u64(), Some(2));
    assert_eq!(doc["harmonics"][0].as_u64(), Some(40));
    let omega: Vec<f64> = doc["omega"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_f64().unwrap())
        .collect();
    let expected: Vec<f64> = b.response.points.iter().map(|p| p.omega).collect();
    assert_eq!(omega, expected);
    assert_eq!(doc["stable"].as_array().unwrap().len(), expected.len());
    assert_eq!(doc["from_event"]["kind"], "period-doubling");
    assert_eq!(
        doc["next_event"]["omega"].as_f64(),
        b.next_event.map(|e| e.omega)
    );
    // The period-2 branch is on the forcing frequency's scale, beside the event it left.
    let from = doc["from_event"]["omega"].as_f64().unwrap();
    assert!((omega[0] - from).abs() < 0.05, "{} vs {from}", omega[0]);
}

#[test]
fn sweep_csv_rows_carry_the_period_two_points_after_the_sweeps_own() {
    use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
    let r = bilinear_sweep(true);
    let branches: Vec<_> = (r.period_two.iter())
        .filter_map(|o| match o {
            PeriodTwoOutcome::Followed(b) => Some(&b.response),
            _ => None,
        })
        .collect();
    assert!(!branches.is_empty(), "{:?}", r.period_two);
    let table = ssn::sweep_table::sweep_columns(&r);
    let column = |name: &str| &table.iter().find(|(n, _)| n == name).unwrap().1;
    let rows = r.points.len() + branches.iter().map(|b| b.points.len()).sum::<usize>();
    assert!(table.iter().all(|(_, values)| values.len() == rows));
    // The sweep's own rows first (branch 0, period 1), then each branch's in its order.
    let mut start = r.points.len();
    let sweep_omega: Vec<f64> = r.points.iter().map(|p| p.omega).collect();
    assert_eq!(column("omega")[..start], sweep_omega[..]);
    assert!(column("branch")[..start].iter().all(|&b| b == 0.0));
    assert!(column("period_multiple")[..start].iter().all(|&m| m == 1.0));
    for (k, b) in branches.iter().enumerate() {
        let end = start + b.points.len();
        let omega: Vec<f64> = b.points.iter().map(|p| p.omega).collect();
        assert_eq!(column("omega")[start..end], omega[..]);
        assert_eq!(column("amplitude")[start..end], b.amplitudes()[..]);
        assert!(column("branch")[start..end]
            .iter()
            .all(|&v| v == (k + 1) as f64));
        assert!(column("period_multiple")[start..end]
            .iter()
            .all(|&m| m == 2.0));
        start = end;
    }
    // Without period-2 branches the table has neither column.
    let plain = bilinear_sweep(false);
    let names: Vec<String> = (ssn::sweep_table::sweep_columns(&plain).into_iter())
        .map(|(n, _)| n)
        .collect();
    assert!(
        !names
            .iter()
            .any(|n| n == "branch" || n == "period_multiple"),
        "{names:?}"
    );
}
