//! Harmonics chosen point by point along a branch for an accuracy target
//! ([`SolverSettings::accuracy`], module `sweep::adaptive`), on the paper's rod (`p0 =
//! 0.04`, gap 0.5, the massless contact node of the modified mass) around its resonance:
//! every point, through the overhang and its folds, against SSN-HB at a much finer fixed
//! `H` taken up across the branch at that point (the same solution, not whichever the
//! finer harmonics have at the point's frequency), and the harmonics larger in contact
//! than in the linear tail.

use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::sweep::adaptive::{point_distance, secant, take_up};
use semismooth_contact::sweep::frequency_response;

/// Harmonics of the refined solves the points are checked against.
const REFINED: usize = 160;

#[test]
fn every_point_of_an_adaptive_sweep_meets_its_target_against_the_refined_branch(
) -> Result<(), Box<dyn std::error::Error>> {
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })?;
    // A target the sweep meets with a few dozen harmonics (1e-3 takes about 200 over the
    // resonance: examples/adaptive_sweep.rs in ssn).
    let target = 1e-2;
    let settings = SolverSettings {
        accuracy: Some(target),
        ..SolverSettings::default()
    };
    let sweep = SweepSettings {
        stability: false,
        ..SweepSettings::new(0.8, 1.2)
    };
    let r = frequency_response(&rod, &settings, &sweep, None)?;
    assert!(r.converged(), "{}", r.termination);
    assert!(r.points.iter().all(|p| p.harmonics.is_some()));
    let accuracy = r.accuracy.as_ref().expect("an adaptive sweep");
    // Every point is estimated and its estimate meets the target.
    assert!(
        r.points
            .iter()
            .flat_map(|p| p.error_estimate)
            .all(|e| e <= target),
        "{accuracy:?}"
    );
    assert_eq!(accuracy.met(&r.points), r.points.len(), "{accuracy:?}");

    // The linear tail needs few harmonics, the contact many.
    let first = r.harmonics()[0];
    let most = *r.harmonics().iter().max().unwrap();
    assert!(
        r.points[0].contacts[0].force_mean == 0.0,
        "no contact at 0.8 omega_1"
    );
    assert!(most >= 4 * first, "harmonics {:?}", r.harmonics());

    // Each point against SSN-HB at H = 160 taken up across the branch there (normal to
    // the sweep's secant): its distance (extremes relative to the reference's largest
    // excursion, and frequency), within the target, and the estimate neither below a
    // third of it nor above ten times it where it is above round-off.
    let (dofs, contacts) = (rod.model.dofs(), rod.model.contact_count());
    let refined = SolverSettings {
        estimate_error: false,
        ..SolverSettings::with_harmonics(REFINED)
    };
    let mut worst = 0.0f64;
    let mut unreferenced = Vec::new();
    for (i, p) in r.points.iter().enumerate() {
        let direction = secant(&r, i, dofs, contacts);
        let h = p.harmonics.expect("a harmonic-balance point");
        let point = (p.state.as_slice(), p.omega, h);
        let Some((state, omega)) = take_up(&rod, &refined, &sweep, point, &direction, REFINED)?
        else {
            unreferenced.push(i);
            continue;
        };
        let reference = solve(&rod, omega, &refined, Some(&state))?;
        assert!(
            reference.converged(),
            "point {i}: the reference solves again"
        );
        let (max, min) = (reference.stats.max, reference.stats.min);
        let error = point_distance((p.observed_max, p.observed_min, p.omega), (max, min, omega));
        worst = worst.max(error);
        let estimate = p.error_estimate;
        assert!(
            error <= target,
            "point {i} at {} omega_1, H = {}: error {error:e}, estimate {estimate:?}",
            p.omega / rod.omega_1,
            h,
        );
        // Below a hundredth of the target both numbers are round-off and the extremes'
        // sampling on two time grids (about 1e-6).
        if error > 0.01 * target {
            let estimate = estimate.expect("an estimate where the error is not round-off");
            assert!(
                error <= 3.0 * estimate && estimate <= 10.0 * error,
                "point {i}: error {error:e}, estimate {estimate:e}"
            );
        }
    }
    assert!(
        unreferenced.len() <= 2,
        "no reference at points {unreferenced:?}"
    );
    println!(
        "worst error {worst:e} over {} points (no reference at {unreferenced:?}), harmonics \
         {first} to {most}",
        r.points.len()
    );
    Ok(())
}
