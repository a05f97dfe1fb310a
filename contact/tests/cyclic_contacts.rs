//! Contacts between neighbouring sectors of a tuned bladed disk (an under-platform damper
//! from each blade's pad to the next sector's blade and disk): the cyclic sector, whose
//! rows read the next sector's dofs through the per-harmonic rotation, against the full
//! disk with the same rows between every pair of neighbours, under engine orders 0, 3 and 7,
//! frictionless and with Coulomb friction on the damper.

use semismooth_contact::cyclic::{CyclicSector, InvalidSector};
use semismooth_contact::model::{ContactPoint, ContactRow, InvalidModel, NeighbourRow, Structure};
use semismooth_contact::settings::{LinearSolverChoice, Method, SolverSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::structures::{BladeDamper, DiskLoading};

#[path = "common/sector.rs"]
mod sector;
use sector::{converged, engine_order_disk, nodal_diameter_resonance, settings};
use sector::{relative_recovery_gap, tuned_disk as disk, BLADES};

/// The damper's clearance: the pads close on the neighbours near each resonance.
const GAP: f64 = 0.2;
const MU: f64 = 0.3;

fn loading() -> DiskLoading {
    DiskLoading::shipped(Vec::new())
}

fn damper(friction: bool) -> BladeDamper {
    BladeDamper {
        gap: GAP,
        friction: if friction { MU } else { 0.0 },
    }
}

/// The full disk with a damper between every pair of neighbours (rows written blade by
/// blade on the disk's dofs) and the engine-order load.
fn full_disk(engine_order: usize, friction: bool) -> Structure {
    let disk = disk();
    let mut structure = engine_order_disk(&disk, &loading(), engine_order);
    damper(friction).add_to_disk(&disk, &mut structure.model);
    structure
}

/// The sector with the same damper: its own part on the sector's pad (and tip), the
/// neighbour part on the next sector's tip and disk dof.
fn sector(engine_order: usize, friction: bool) -> CyclicSector {
    let (sector, _) = disk().cyclic_sector(&loading(), engine_order).unwrap();
    damper(friction).add_to_sector(&sector).unwrap()
}

/// Solves the full disk (with the first of `runs`) and the sector (with each) at the
/// resonance of the engine order's nodal diameter and returns the largest relative recovery
/// gap.
fn sector_against_full_disk(engine_order: usize, friction: bool, runs: &[SolverSettings]) -> f64 {
    let harmonics = runs[0].harmonics;
    let full = full_disk(engine_order, friction);
    let sector = sector(engine_order, friction);
    let structure = sector.structure(1).unwrap();
    let omega = nodal_diameter_resonance(&sector);
    let reference = converged(&full, omega, &runs[0]);
    let fractions: Vec<f64> = (reference.contacts.iter())
        .map(|c| c.contact_fraction)
        .collect();
    // The damper closes for part of the period on every blade: the contact law is active.
    assert!(
        fractions.iter().all(|f| *f > 0.0 && *f < 1.0),
        "EO {engine_order}: contact fractions {fractions:?}"
    );
    let mut worst = 0.0f64;
    for run in runs {
        let solution = converged(&structure, omega, run);
        let gap = relative_recovery_gap(&sector, &solution.state, &reference.state, harmonics);
        let (method, choice) = (run.method, run.linear_solver);
        eprintln!("EO {engine_order} friction {friction} {method:?} {choice:?}: gap {gap:e}");
        worst = worst.max(gap);
    }
    worst
}

#[test]
fn a_sector_with_frictionless_dampers_between_sectors_solves_the_full_disk_under_engine_orders_0_3_and_7(
) {
    let runs = [
        LinearSolverChoice::Structured,
        LinearSolverChoice::Dense,
        LinearSolverChoice::CondensedDense,
        LinearSolverChoice::CondensedKrylov,
    ]
    .map(|choice| settings(5, choice));
    for engine_order in [0, 3, 7] {
        let gap = sector_against_full_disk(engine_order, false, &runs);
        // Both converge to residuals below 1e-13 on damped, well-conditioned Jacobians
        // with the same active samples: 1e-10 leaves a wide margin over the roundings.
        assert!(gap < 1e-10, "EO {engine_order}: {gap:e}");
    }
}

#[test]
fn a_sector_with_friction_dampers_between_sectors_solves_the_full_disk_under_engine_orders_0_3_and_7(
) {
    let runs = [LinearSolverChoice::Structured, LinearSolverChoice::Dense]
        .map(|choice| settings(5, choice));
    for engine_order in [0, 3, 7] {
        let gap = sector_against_full_disk(engine_order, true, &runs);
        // As without friction: the same discrete equations, converged below 1e-13.
        assert!(gap < 1e-10, "EO {engine_order}: {gap:e}");
    }
}

#[test]
fn a_penalty_sector_with_dampers_between_sectors_solves_the_penalty_full_disk() {
    let runs =
        [LinearSolverChoice::Structured, LinearSolverChoice::Dense].map(|choice| SolverSettings {
            method: Method::PenaltyHb,
            penalty_stiffness: Some(100.0),
            ..settings(5, choice)
        });
    for engine_order in [0, 3] {
        let gap = sector_against_full_disk(engine_order, false, &runs);
        // The same penalty equations on both (one k_p), converged below 1e-13.
        assert!(gap < 1e-10, "EO {engine_order}: {gap:e}");
    }
}

#[test]
fn rows_between_sectors_on_a_missing_row_or_the_right_interface_are_refused() {
    let (sector, _) = disk().cyclic_sector(&loading(), 3).unwrap();
    let model = sector
        .model()
        .clone()
        .with_contact(ContactPoint::new(2, GAP));
    let new = || CyclicSector::new(model.clone(), vec![0], vec![3], BLADES, 3).unwrap();
    let row = |row: usize, dof: usize| NeighbourRow {
        row,
        part: ContactRow::unit(dof, -1.0),
    };
    assert_eq!(
        new().with_neighbour_rows(vec![row(1, 1)]).err(),
        Some(InvalidSector::Model(InvalidModel::NeighbourRow {
            row: 1,
            rows: 1,
            dof: 1,
            dofs: 4
        }))
    );
    assert_eq!(
        new().with_neighbour_rows(vec![row(0, 3)]).err(),
        Some(InvalidSector::RowOnRightInterface { row: 0, dof: 3 })
    );
}

#[test]
fn a_sector_sweep_with_friction_dampers_between_sectors_is_the_full_disk_at_every_point() {
    use semismooth_contact::settings::SweepSettings;
    use semismooth_contact::sweep::frequency_response;
    let (engine_order, harmonics) = (3, 5);
    let sector = sector(engine_order, true);
    let structure = sector.structure(1).unwrap();
    let full = full_disk(engine_order, true);
    let resonance = nodal_diameter_resonance(&sector);
    let ratio = resonance / structure.omega_1;
    let sweep = SweepSettings {
        stability: false,
        step: 0.002,
        max_step: 0.004,
        ..SweepSettings::new(0.97 * ratio, 1.03 * ratio)
    };
    let run = settings(harmonics, LinearSolverChoice::Structured);
    let response = frequency_response(&structure, &run, &sweep, None).unwrap();
    assert!(response.converged(), "{:?}", response.termination);
    assert!(
        response.points.len() > 10,
        "{} points",
        response.points.len()
    );
    let len = 3 * BLADES * (2 * harmonics + 1);
    let (mut worst, mut closed) = (0.0f64, 0);
    for point in &response.points {
        let recovered = disk().recover_state(&sector, &point.state, harmonics);
        // The full disk solved at the sector's frequency from the recovered state moved by
        // 1e-3 (a start near the point, not on it): Newton returns to the full disk's
        // solution there, which is the recovered state only if the sector solved the disk.
        let start: Vec<f64> = recovered.iter().map(|v| v * 1.001).collect();
        let solution = solve(&full, point.omega, &run, Some(&start)).unwrap();
        assert!(solution.converged() && solution.iterations > 0);
        closed += usize::from(solution.contacts.iter().any(|c| c.contact_fraction > 0.0));
        let u = &solution.state[..len];
        let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let gap = (u.iter().zip(&recovered)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        worst = worst.max(gap / scale);
    }
    eprintln!(
        "{} points, {closed} with the damper closing: largest relative gap {worst:e}",
        response.points.len()
    );
    assert!(closed > 0);
    // Each point converged below 1e-13 on both models (same discrete equations): 1e-10.
    assert!(worst < 1e-10, "{worst:e}");
}
