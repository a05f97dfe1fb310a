//! Turning points of a frequency-response branch against its corners: the folds of the
//! paper's rod (consistent mass, p0 = 0.04, gap 0.5, H = 20) do not depend on the step,
//! while fine steps resolve many small reversals of the frequency where AFT samples enter
//! contact, and a stiff penalty branch turns back a little at many of its corners; those
//! are listed as corners.

use semismooth_contact::rod::build_rod;
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};
use ssn::scene::Scene;

/// The paper's rod with `method`, initial step `step` and, when given, `max_step`.
fn sweep(method: &str, step: f64, max_step: Option<f64>) -> FrequencyResponse {
    let text = format!(
        "[rod]\nelements = 20\n[damping]\nzeta = 0.01\n\
         [forcing]\namplitude = 0.04\nomega_ratio = 1.0\n[contact]\ngap = 0.5\n\
         [solver]\nmethod = \"{method}\"\nharmonics = 20\n{}\
         [sweep]\nomega_ratio_from = 0.5\nomega_ratio_to = 2.0\nstep = {step}\n{}",
        if method == "penalty-hb" {
            "penalty_stiffness = 1000\n"
        } else {
            ""
        },
        max_step.map_or(String::new(), |m| format!("max_step = {m}\n"))
    );
    let scene = Scene::from_toml(&text, "<test>").unwrap();
    let rod = build_rod(&scene.rod).unwrap();
    let r = frequency_response(&rod, &scene.solver, scene.sweep.as_ref().unwrap(), None).unwrap();
    assert!(r.converged(), "{}", r.termination);
    r
}

fn ratios(r: &FrequencyResponse, w: &[f64]) -> Vec<f64> {
    w.iter().map(|w| w / r.omega_1).collect()
}

/// The two folds (jump-down near 1.0276 and jump-up near 1.0178 omega_1) with the default
/// steps (initial 0.01) and with every step at most 0.002 agree within 5e-4 omega_1
/// (measured 1.1e-4 and 2.7e-4: the coarse steps step over the zigzags of up to 1.1e-3
/// omega_1 that the fine ones resolve).
#[test]
fn fold_count_does_not_depend_on_the_step() {
    let coarse = sweep("ssn-hb", 0.01, None);
    let fine = sweep("ssn-hb", 0.002, Some(0.002));
    let (a, b) = (ratios(&coarse, &coarse.folds), ratios(&fine, &fine.folds));
    println!(
        "step 0.01: {} points, folds {a:?}, {} corner reversals; step 0.002: {} points, \
         folds {b:?}, {} corner reversals",
        coarse.points.len(),
        coarse.corner_folds.len(),
        fine.points.len(),
        fine.corner_folds.len()
    );
    assert_eq!(a.len(), 2);
    assert_eq!(b.len(), 2);
    assert!(
        a[0] > a[1],
        "first the upper fold (jump down), then the lower"
    );
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 5e-4, "{a:?} against {b:?}");
    }
    assert!(
        (a[0] - 1.0276).abs() < 1e-3 && (a[1] - 1.0178).abs() < 1e-3,
        "{a:?}"
    );
}

/// The fine sweep resolves the small reversals (36 measured, of at most 1.1e-3 omega_1),
/// and they are corners; so are the 146 reversals of the penalty branch at k_p = 1000,
/// whose two folds are those of SSN-HB within 1.5e-3 omega_1 (the penalty's penetration
/// moves the upper fold: 1.0289 against 1.0276, measured).
#[test]
fn small_reversals_and_penalty_corners_are_listed_as_corners() {
    let fine = sweep("ssn-hb", 0.002, Some(0.002));
    let penalty = sweep("penalty-hb", 0.01, None);
    println!(
        "ssn-hb step 0.002: {} corner reversals; penalty k_p = 1000: {} points, folds {:?}, \
         {} corner reversals",
        fine.corner_folds.len(),
        penalty.points.len(),
        ratios(&penalty, &penalty.folds),
        penalty.corner_folds.len()
    );
    assert!(fine.corner_folds.len() >= 10, "{}", fine.corner_folds.len());
    assert!(
        penalty.corner_folds.len() >= 30,
        "{}",
        penalty.corner_folds.len()
    );
    for (r, list) in [
        (&fine, &fine.corner_folds),
        (&penalty, &penalty.corner_folds),
    ] {
        // Every corner lies on the contact part of the branch near the overhang: between
        // the folds, or (penalty) on the way up to the upper fold within 1e-3 omega_1 below
        // the lower one (measured down to 1.01722 against the fold at 1.01783).
        let (hi, lo) = (r.folds[0], r.folds[1] - 1e-3 * r.omega_1);
        let outside: Vec<f64> = list
            .iter()
            .filter(|w| !(lo - 1e-9 <= **w && **w <= hi + 1e-9))
            .map(|w| w / r.omega_1)
            .collect();
        assert!(
            outside.is_empty(),
            "{outside:?} outside {:?}",
            ratios(r, &r.folds)
        );
        assert_eq!(r.corner_folds.len(), r.corner_fold_indices.len());
    }
    let (a, b) = (ratios(&fine, &fine.folds), ratios(&penalty, &penalty.folds));
    assert_eq!(b.len(), 2);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1.5e-3, "{a:?} against {b:?}");
    }
    let json = ssn::json::response_json(&penalty);
    assert_eq!(json["folds"].as_array().unwrap().len(), 2);
    assert_eq!(
        json["corner_folds"].as_array().unwrap().len(),
        penalty.corner_folds.len()
    );
}
