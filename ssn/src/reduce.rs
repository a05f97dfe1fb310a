//! A scene's `[reduction]` applied to its structure: Craig–Bampton onto the contact,
//! friction, observed and loaded dofs (`semismooth_contact::reduction`). The reduced
//! structure keeps the full model's `omega_1` as the unit of the scene's frequency ratios;
//! `modal_damping` replaces its damping.

use semismooth_contact::model::Structure;
use semismooth_contact::reduction::{
    boundary_dofs, craig_bampton, massless_boundary, modal_damping, CraigBampton,
};

use crate::scene::{ReductionMethod, ReductionSpec, Scene};

/// `full` reduced as `spec` says, for the scene's forcing frequency `omega` (a cut-off is a
/// multiple of the highest harmonic's frequency); the error in words.
pub fn reduce(
    scene: &Scene,
    spec: &ReductionSpec,
    full: &Structure,
    omega: f64,
) -> Result<CraigBampton, String> {
    let modes = spec.mode_count(omega, scene.solver.harmonics);
    let boundary = boundary_dofs(full, &[]);
    let mut reduced = match spec.method {
        ReductionMethod::CraigBampton => craig_bampton(full, &boundary, modes),
        ReductionMethod::MasslessBoundary => massless_boundary(full, &boundary, modes),
    }
    .map_err(|e| format!("[reduction]: {e}"))?;
    reduced.structure.omega_1 = full.omega_1;
    if let Some(zeta) = spec.modal_damping {
        let model = &mut reduced.structure.model;
        model.damping = Some(modal_damping(model, zeta).map_err(|e| format!("[reduction]: {e}"))?);
    }
    Ok(reduced)
}

/// The lines `ssn scene-check` adds for a reduction: the sizes, and the first natural
/// frequencies of the reduced model beside the full model's.
pub fn reduction_lines(
    method: ReductionMethod,
    reduced: &CraigBampton,
    full: &[f64],
    reduced_freqs: &[f64],
) -> String {
    let size = reduced.structure.model.dofs();
    let kept = &reduced.interface_frequencies;
    let mut t = format!(
        "reduction         {}: {} dofs -> {size} ({} boundary dofs, {} \
         {}-interface modes{})\n",
        method.name(),
        reduced.transform.first().map_or(0, Vec::len),
        reduced.boundary.len(),
        kept.len(),
        match method {
            ReductionMethod::CraigBampton => "fixed",
            ReductionMethod::MasslessBoundary => "free",
        },
        kept.last()
            .map_or(String::new(), |w| format!(" up to {w:.6}")),
    );
    let list = |v: &[f64]| {
        v.iter()
            .map(|w| format!("{w:.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    t.push_str(&format!("full freqs        {}\n", list(full)));
    t.push_str(&format!("reduced freqs     {}\n", list(reduced_freqs)));
    t
}
