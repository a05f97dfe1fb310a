//! The paper's Fig. 2 rod (consistent mass, gap 0.5): the jumps of a slow time-marching
//! experiment, up and down in frequency, fall at the folds of the harmonic-balance branch
//! of the figure (`H = 5`) to within that branch's truncation error.

#[path = "common/stepped_march.rs"]
mod stepped_march;

use semismooth_contact::march::{MarchOptions, MarchScheme};
use semismooth_contact::rod::{build_rod, RodSpec};
use stepped_march::{branch_folds, jump, stepped_amplitudes};

/// Frequency step of the marching sweeps, in `omega_1`.
const STEP: f64 = 0.004;

#[test]
fn marching_jumps_up_and_down_fall_at_the_folds_within_the_truncation_error() {
    let rod = build_rod(&RodSpec::canonical().with_tip_gap(Some(0.5))).unwrap();
    let w1 = rod.omega_1;
    let (folds_5, folds_20) = (branch_folds(&rod, 5), branch_folds(&rod, 20));
    assert_eq!(
        (folds_5.len(), folds_20.len()),
        (2, 2),
        "{folds_5:?} {folds_20:?}"
    );
    // Up from omega_1 (on the contact branch, where marching from rest settles) to 1.036,
    // past the marched jump (1.0276 measured with steps of 0.002), and back down.
    let up: Vec<f64> = (0..10).map(|k| (1.0 + k as f64 * STEP) * w1).collect();
    let down: Vec<f64> = up.iter().rev().copied().collect();
    let options = MarchOptions {
        steps_per_period: 400,
        tolerance: 1e-6,
        max_periods: 1500,
        scheme: MarchScheme::MOREAU_JEAN_DEFAULT,
    };
    let a_up = stepped_amplitudes(&rod.model, &up, &options, rod.tip_dof());
    let a_down = stepped_amplitudes(&rod.model, &down, &options, rod.tip_dof());
    let (jump_up, drop) = jump(&up, &a_up);
    let (jump_down, rise) = jump(&down, &a_down);
    println!("up: {a_up:.4?}\ndown: {a_down:.4?}");
    println!(
        "jumps up {:.4} (amplitude -{drop:.3}), down {:.4} (+{rise:.3}); folds H = 5 {folds_5:.4?}, H = 20 {folds_20:.4?}",
        jump_up / w1,
        jump_down / w1
    );
    // A jump is located to half a step. The fold of the truncated branch is off by its
    // truncation error, estimated by the change from H = 5 to H = 20 (1.4e-2 at the upper
    // fold, 5e-4 at the lower one): the marched jump lies within that error plus half a
    // step of the figure's fold, and within half a step plus 2e-3 (Moreau–Jean's impacts
    // are first order in the step, 400 per period) of the H = 20 fold.
    for (jump, fold_5, fold_20) in [
        (jump_up / w1, folds_5[0], folds_20[0]),
        (jump_down / w1, folds_5[1], folds_20[1]),
    ] {
        let truncation = (fold_5 - fold_20).abs();
        assert!(
            (jump - fold_5).abs() <= truncation + 0.5 * STEP + 2e-3,
            "jump {jump} against the H = 5 fold {fold_5} (H = 20: {fold_20})"
        );
        assert!(
            (jump - fold_20).abs() <= 0.5 * STEP + 2e-3,
            "jump {jump} against the H = 20 fold {fold_20}"
        );
    }
    // The jumps are jumps: the upper branch ends at 0.53 and the lower branch meets the stop.
    assert!(drop > 0.1 && rise > 0.03, "{drop} {rise}");
}
