//! What the outputs reconstruct from a harmonic-balance solution, offered alike by both
//! harmonic-balance problems.

use crate::contacts::FrictionReport;
use crate::hb::{HbError, PenaltyHb, SsnHb};

/// Reconstruction a harmonic-balance problem offers for the outputs.
pub(crate) trait HbReconstruction {
    fn displacement(&self, x: &[f64], dof: usize, points: usize) -> Result<Vec<f64>, HbError>;
    /// Contact `i`'s force, its law applied to the samples (never tension).
    fn contact_force(&self, x: &[f64], i: usize, points: usize) -> Result<Vec<f64>, HbError>;
    /// Contact `i`'s force as its truncated Fourier series, where the method has one (it
    /// may ring above zero around the contact's transitions).
    fn contact_force_series(
        &self,
        x: &[f64],
        i: usize,
        points: usize,
    ) -> Result<Option<Vec<f64>>, HbError>;
    /// The fractions of the period where contact `i`'s law is active (closed).
    fn closed_intervals(&self, x: &[f64], i: usize) -> Result<Vec<(f64, f64)>, HbError>;
    /// `g_i . u` of row `i` of `G`.
    fn row_displacement(&self, x: &[f64], i: usize, points: usize) -> Result<Vec<f64>, HbError>;
    /// Friction point `f` over one period on `points` times.
    fn friction(&self, x: &[f64], f: usize, points: usize) -> Result<FrictionReport, HbError>;
}

/// Both harmonic-balance problems reconstruct through the same inherent methods, but for
/// their force samples (`$law`) and series (`$series`).
macro_rules! hb_reconstruction {
    ($($problem:ty => $law:ident, $series:expr);*) => {$(
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
                self.$law(x, i, points)
            }
            fn contact_force_series(
                &self,
                x: &[f64],
                i: usize,
                points: usize,
            ) -> Result<Option<Vec<f64>>, HbError> {
                let series: fn(&$problem, &[f64], usize, usize) -> _ = $series;
                series(self, x, i, points)
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

hb_reconstruction!(
    SsnHb => contact_force_law_samples, |p, x, i, points| p.contact_force_samples(x, i, points).map(Some);
    PenaltyHb => contact_force_samples, |_, _, _, _| Ok(None)
);
