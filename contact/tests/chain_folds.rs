//! The two-dof chain with a stop on its free mass (a contact on a dof that carries mass):
//! its frequency response passes every contact corner from 0.5 to 3 `ω_1`, and the folds
//! it reports are those of the resolved response, however coarse the harmonic balance.

#[path = "common/chain.rs"]
mod chain;

use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

/// A force 0.1 on the free mass, a stop at 0.5 from it, 2 % damping at the first mode.
fn sweep(harmonics: usize) -> FrequencyResponse {
    let settings = SolverSettings::with_harmonics(harmonics);
    frequency_response(
        &chain::chain(0.5, 0.02, [0.0, 0.1]),
        &settings,
        &SweepSettings::new(0.5, 3.0),
        None,
    )
    .unwrap()
}

#[test]
fn chain_with_a_stop_on_its_mass_has_the_two_folds_of_the_resolved_response_at_every_h() {
    let reference = sweep(40);
    let w1 = reference.omega_1;
    let folds = |r: &FrequencyResponse| r.folds.iter().map(|w| w / w1).collect::<Vec<_>>();
    let resolved = folds(&reference);
    println!(
        "H = 40: {} points, folds {resolved:?}, {} corner reversals",
        reference.points.len(),
        reference.corner_folds.len()
    );
    assert!(reference.converged(), "{:?}", reference.termination);
    // The hardening overhang of the stop: up to the upper fold, back to the lower one.
    assert_eq!(resolved.len(), 2, "{resolved:?}");
    assert!(resolved[0] > resolved[1]);
    for h in [10, 20] {
        let r = sweep(h);
        let f = folds(&r);
        println!(
            "H = {h}: {} points, folds {f:?}, {} corner reversals",
            r.points.len(),
            r.corner_folds.len()
        );
        // The whole range, passing every corner.
        assert!(r.converged(), "H = {h}: {:?}", r.termination);
        let last = r.points.last().unwrap().omega / w1;
        assert!((last - 3.0).abs() < 1e-12, "H = {h} ends at {last}");
        // The branch turns back by 2e-3 to 3.4e-3 omega_1 several times below the
        // resonance at H = 10 and 20 (zigzags of the truncated balance, gone at H = 40):
        // those are corner reversals, and the folds are the resolved response's two. The
        // upper fold moves with the truncation (measured 1.2621, 1.2642, 1.2667 at H = 10,
        // 20, 40: 1e-2 bounds the distance), the lower one hardly (1.16886, 1.16888,
        // 1.16890: 5e-4).
        assert_eq!(f.len(), 2, "H = {h}: {f:?}");
        assert!((f[0] - resolved[0]).abs() < 1e-2, "H = {h}: {f:?}");
        assert!((f[1] - resolved[1]).abs() < 5e-4, "H = {h}: {f:?}");
    }
}
