//! The round-off floor a harmonic-balance run is judged against: the `|F|` that
//! floating point alone leaves near a solution, in proportion to the displacements.

use semismooth::newton::StateFloor;
use semismooth::Residual;

use crate::hb::{PenaltyHb, SsnHb};

/// The largest Newton tolerance of a forced harmonic-balance run relative to its load's
/// size (see [`load_scaled_tolerance`]): six digits of the load balanced at least.
pub(crate) const LOAD_RELATIVE_TOLERANCE: f64 = 1e-6;

/// The Newton tolerance of a forced harmonic-balance run, in force units: `tolerance`, but
/// at most [`LOAD_RELATIVE_TOLERANCE`] times the load's size `|f|` (the 2-norm of all its
/// harmonic coefficients, the residual at the zero guess). A small load (a model in other
/// units) is then solved to a relative accuracy instead of passing at the zero guess; a
/// large one keeps the absolute tolerance, which the round-off floor raises with the
/// response ([`displacement_floor`]). A model without load (driven by its obstacles) keeps
/// `tolerance`.
pub(crate) fn load_scaled_tolerance(tolerance: f64, model: &crate::model::StructuralModel) -> f64 {
    let squares = (model.load.harmonics().iter())
        .flat_map(|h| h.cosine.iter().chain(&h.sine))
        .map(|v| v * v)
        .sum::<f64>();
    let size = squares.sqrt();
    if size > 0.0 {
        tolerance.min(LOAD_RELATIVE_TOLERANCE * size)
    } else {
        tolerance
    }
}

/// Round-off level of a harmonic-balance residual: one ulp of the largest force term,
/// `eps max_i K_ii sqrt(n) max|u|`. A Newton run that stalls (the step no longer moves
/// the iterate) within 100 times of it has converged as far as floating point allows:
/// large models (10^5 elements, 4 10^6 unknowns) stall near 1e-9 in force units.
pub(crate) fn roundoff_floor(
    model: &crate::model::StructuralModel,
    dim: usize,
    u_max: f64,
    extra_stiffness: f64,
) -> f64 {
    let k_max = (0..model.dofs())
        .map(|i| crate::model::diagonal_entry(&model.stiffness, i).abs())
        .fold(extra_stiffness, f64::max);
    f64::EPSILON * k_max * (dim as f64).sqrt() * u_max
}

/// The round-off floor of a harmonic-balance residual at an iterate whose first
/// `displacements` entries are displacement coefficients: [`roundoff_floor`] with `max|u|`
/// the iterate's largest displacement coefficient, capped by the largest gap when the model
/// has contact rows (a closed contact's dof reaches its gap, an open one's never does: a
/// floor scaled by a large gap alone would pass the zero guess) and uncapped without them
/// (a linear response near resonance, whose round-off grows with it).
pub(crate) fn displacement_floor(
    model: &crate::model::StructuralModel,
    dim: usize,
    displacements: usize,
    extra_stiffness: f64,
) -> StateFloor {
    let cap = if model.row_count() == 0 {
        f64::INFINITY
    } else {
        model
            .contacts
            .iter()
            .fold(0.0f64, |a, c| a.max(c.gap.abs()))
            .max(f64::MIN_POSITIVE)
    };
    StateFloor {
        per_unit: roundoff_floor(model, dim, 1.0, extra_stiffness),
        entries: Some(displacements),
        cap,
    }
}

/// A harmonic-balance problem whose unknowns start with the displacement coefficients.
pub(crate) trait DisplacementBlock {
    /// How many leading unknowns are displacement coefficients.
    fn displacement_len(&self) -> usize;
}

impl DisplacementBlock for SsnHb {
    fn displacement_len(&self) -> usize {
        SsnHb::displacement_len(self)
    }
}

impl DisplacementBlock for PenaltyHb {
    fn displacement_len(&self) -> usize {
        // Penalty HB's unknowns are the displacement coefficients alone.
        self.dim()
    }
}
