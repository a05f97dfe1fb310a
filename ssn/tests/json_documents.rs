//! The JSON documents of the program against the results they print.

mod common;

use semismooth_contact::rod::MassModel;
use semismooth_contact::settings::{Method, SweepSettings};
use semismooth_contact::sweep::frequency_response;

#[test]
fn sweep_json_has_the_documented_fields_one_entry_per_point() {
    let rod = common::fig2_rod_model(Some(0.5), 0.04, MassModel::Consistent);
    let r = frequency_response(
        &rod,
        &common::sweep_solver(Method::SsnHb, 3),
        &SweepSettings::new(0.8, 1.2),
        None,
    )
    .unwrap();
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

#[test]
fn sweep_json_carries_the_period_two_branch_with_period_multiple_two() {
    use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
    let mut sweep = SweepSettings::new(1.5, 3.2);
    sweep.step = 0.02;
    sweep.period_two = true;
    let r = frequency_response(
        &bilinear_oscillator(),
        &common::sweep_solver(Method::SsnHb, 20),
        &sweep,
        None,
    )
    .unwrap();
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
