//! A structure built from its matrices in code, solved, swept and reported per contact,
//! with the library alone (no scene file, no `ssn`).
//!
//! `cargo run --release -p semismooth-contact --example structure_from_matrices`

use semismooth_contact::builder::sparse_matrix;
use semismooth_contact::model::{ContactDirection, ContactPoint, StructuralModel, Structure};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::frequency_response;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A disk (dof 0) and a blade (dof 1) of unit mass, and a massless pad (dof 2) on a stiff
    // spring between stops on both sides (a massless contact dof needs no impact law).
    let (kd, kb, kp) = (
        [(0, 0, 2.0), (0, 1, -1.0)],
        [(1, 0, -1.0), (1, 1, 11.0)],
        10.0,
    );
    let pad = [(1, 2, -kp), (2, 1, -kp), (2, 2, kp)];
    let k = sparse_matrix(3, &[&kd[..], &kb, &pad].concat())?;
    let m = sparse_matrix(3, &[(0, 0, 1.0), (1, 1, 1.0)])?;
    let below = ContactPoint::on_side(2, 0.6, ContactDirection::Negative); // -u_pad <= 0.6
    let model = StructuralModel::new(m, k, vec![0.0, 0.01, 0.0]) // load on the blade
        .with_rayleigh_damping(0.0, 0.01)
        .with_contact(ContactPoint::new(2, 0.5)) // u_pad <= 0.5
        .with_contact(below);
    let structure = Structure::new(model, 1)?; // the blade is observed
    let settings = SolverSettings::default(); // SSN-HB, H = 20, from zero
    let w1 = structure.omega_1;
    let s = semismooth_contact::solve(&structure, w1, &settings, None)?;
    let (it, end) = (s.iterations, s.termination);
    let (lo, hi) = (s.stats.min, s.stats.max);
    println!("at omega_1 = {w1:.4}: {end} in {it} iterations, blade in [{lo:.4}, {hi:.4}]");
    for c in &s.contacts {
        let (dof, gap, force, closed) = (c.dof, c.gap, c.force_mean, 100.0 * c.contact_fraction);
        println!("  stop on dof {dof} (gap {gap}): mean force {force:+.3e}, closed {closed:.1} %");
    }
    let branch = frequency_response(&structure, &settings, &SweepSettings::new(0.6, 1.6), None)?;
    let (peak, amplitude) = branch.peak().ok_or("an empty branch")?;
    let stable = branch
        .points
        .iter()
        .filter(|p| p.stability.stable == Some(true))
        .count();
    let folds = branch.folds.iter().map(|w| format!("{:.4}", w / w1));
    let (points, complete, at) = (
        branch.points.len(),
        branch.converged(),
        branch.points[peak].omega / w1,
    );
    println!("sweep over [0.6, 1.6] omega_1: {points} points, complete {complete}");
    println!("  {stable} stable, peak {amplitude:.4} at {at:.4} omega_1");
    println!(
        "  folds at {} omega_1",
        folds.collect::<Vec<_>>().join(", ")
    );
    Ok(())
}
