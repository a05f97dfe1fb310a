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
