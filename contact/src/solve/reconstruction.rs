//! What the outputs reconstruct from a harmonic-balance solution, offered alike by both
//! harmonic-balance problems.

use crate::contacts::FrictionReport;
use crate::hb::{HbError, PenaltyHb, SsnHb};

/// Reconstruction a harmonic-balance problem offers for the outputs.
pub(crate) trait HbReconstruction {
    fn displacement(&self, x: &[f64], dof: usize, points: usize) -> Result<Vec<f64>, HbError>;
    fn contact_force(&self, x: &[f64], i: usize, points: usize) -> Result<Vec<f64>, HbError>;
    /// The fractions of the period where contact `i`'s law is active (closed).
    fn closed_intervals(&self, x: &[f64], i: usize) -> Result<Vec<(f64, f64)>, HbError>;
    /// `g_i . u` of row `i` of `G`.
    fn row_displacement(&self, x: &[f64], i: usize, points: usize) -> Result<Vec<f64>, HbError>;
    /// Friction point `f` over one period on `points` times.
    fn friction(&self, x: &[f64], f: usize, points: usize) -> Result<FrictionReport, HbError>;
}

/// Both harmonic-balance problems reconstruct through the same inherent methods.
macro_rules! hb_reconstruction {
    ($($problem:ty),*) => {$(
        impl HbReconstruction for $problem {
            fn displacement(
                &self,
                x: &[f64],
                dof: usize,
                points: usize,
            ) -> Result<Vec<f64>, HbError> {
                self.displacement_samples(x, dof, points)
            }
            fn contact_force(&self, x: &[f64], i: usize, points: usize) -> Result<Vec<f64>, HbError> {
                self.contact_force_samples(x, i, points)
            }
            fn closed_intervals(&self, x: &[f64], i: usize) -> Result<Vec<(f64, f64)>, HbError> {
                self.closed_intervals(x, i)
            }
            fn row_displacement(
                &self,
                x: &[f64],
                i: usize,
                points: usize,
            ) -> Result<Vec<f64>, HbError> {
                self.row_displacement_samples(x, i, points)
            }
            fn friction(
                &self,
                x: &[f64],
                f: usize,
                points: usize,
            ) -> Result<FrictionReport, HbError> {
                self.friction_report(x, f, points)
            }
        }
    )*};
}

hb_reconstruction!(SsnHb, PenaltyHb);
