//! Every contact of every point of a branch ([`ResponsePoint::contacts`]), with the
//! numbers `ssn solve` reports for one solution ([`ContactReport`]): gap, mean force,
//! largest penetration, fraction of the period in contact, displacement range.
//!
//! Harmonic-balance branches reconstruct the contact displacements and forces on
//! [`FrequencyResponse::output_points`] equally spaced times, as `ssn solve` does; an LCP
//! branch (`lcp-ssn`) has them at its `Nt` time nodes: the state is `(w, z)`, time-major,
//! so contact `c` has displacement `u = g - w[n m + c]` and force `-z[n m + c]` at node `n`.

use crate::contacts::{contact_reports, set_series_means, ContactReport, FrictionSummary};
use crate::model::Structure;
use crate::settings::SolverSettings;
use crate::solve::{set_closed_fractions, HarmonicProblem, HbReconstruction, RunError};

#[cfg(doc)]
use super::ResponsePoint;
use super::{FrequencyResponse, StateRecovery};

/// Per-contact reports and friction summaries of a point, in the model's order of contacts
/// and friction points.
type PointReports = (Vec<ContactReport>, Vec<FrictionSummary>);

/// Sets the per-contact reports of each point of `response` and, for harmonic balance, the
/// friction summaries (none without friction points). Methods that do not sweep have no
/// points.
pub(super) fn set_branch_reports(
    structure: &Structure,
    settings: &SolverSettings,
    response: &mut FrequencyResponse,
) -> Result<(), RunError> {
    let reports = branch_reports(structure, settings, response)?;
    for (point, (contacts, friction)) in response.points.iter_mut().zip(reports) {
        point.contacts = contacts;
        point.friction = friction;
    }
    Ok(())
}

/// The per-contact reports and friction summaries of each point of `response`
/// ([`set_branch_reports`]).
fn branch_reports(
    structure: &Structure,
    settings: &SolverSettings,
    response: &FrequencyResponse,
) -> Result<Vec<PointReports>, RunError> {
    let model = &structure.model;
    let contacts: Vec<(usize, f64)> = model.contacts.iter().map(|c| (c.dof(), c.gap)).collect();
    let friction_points = model.friction.len();
    let points = response.output_points;
    let report = |problem: &dyn HbReconstruction, x: &[f64]| -> Result<_, RunError> {
        let forces = (0..contacts.len())
            .map(|i| problem.contact_force(x, i, points))
            .collect::<Result<Vec<_>, _>>()?;
        let displacements = (0..contacts.len())
            .map(|i| problem.row_displacement(x, i, points))
            .collect::<Result<Vec<_>, _>>()?;
        let closed = (0..contacts.len())
            .map(|i| problem.closed_intervals(x, i))
            .collect::<Result<Vec<_>, _>>()?;
        let series = (0..contacts.len())
            .filter_map(|i| problem.contact_force_series(x, i, points).transpose())
            .collect::<Result<Vec<_>, _>>()?;
        let mut reports = contact_reports(&contacts, &forces, &displacements);
        set_series_means(&mut reports, &contacts, &series, &displacements);
        set_closed_fractions(&mut reports, &closed);
        let friction = (0..friction_points)
            .map(|f| Ok(problem.friction(x, f, points)?.summary))
            .collect::<Result<Vec<_>, RunError>>()?;
        Ok((reports, friction))
    };
    // The reconstructions over one period do not depend on the frequency: any valid one,
    // with the point's harmonics (built again where they change along the branch).
    let omega = structure.omega_1;
    let build = |s: &SolverSettings| -> Result<Box<dyn HbReconstruction>, RunError> {
        let problem = HarmonicProblem::of(model, omega, s)?;
        Ok(problem.into_reconstruction())
    };
    let hb = || -> Result<Vec<PointReports>, RunError> {
        let mut current: Option<((usize, usize), Box<dyn HbReconstruction>)> = None;
        let mut reports = Vec::with_capacity(response.points.len());
        let mut states = StateRecovery::new(structure, settings, response);
        for i in 0..response.points.len() {
            let x = &*states.state(i)?;
            let at = response.point_settings(settings, i);
            let key = (at.harmonics, at.time_samples);
            if current.as_ref().is_none_or(|(k, _)| *k != key) {
                current = Some((key, build(&at)?));
            }
            let (_, problem) = current.as_ref().expect("built above");
            reports.push(report(problem.as_ref(), x)?);
        }
        Ok(reports)
    };
    if settings.method.is_harmonic_balance() {
        return hb();
    }
    // The periodic LCP's states are its contact forces (a branch of lcp-ssn; the other
    // time-domain methods have no branch).
    let m = contacts.len();
    let reports = if settings.method.is_lcp() {
        response
            .points
            .iter()
            .map(|p| (lcp_point_contacts(&contacts, &p.state, m), Vec::new()))
            .collect()
    } else {
        Vec::new()
    };
    Ok(reports)
}

/// The reports of an LCP state `y = (w, z)` with `m` contacts (module documentation).
fn lcp_point_contacts(contacts: &[(usize, f64)], y: &[f64], m: usize) -> Vec<ContactReport> {
    let half = y.len() / 2;
    let (w, z) = y.split_at(half);
    let nodes = half.checked_div(m).unwrap_or(0);
    let forces: Vec<Vec<f64>> = (0..m)
        .map(|c| (0..nodes).map(|n| -z[n * m + c]).collect())
        .collect();
    let displacements: Vec<Vec<f64>> = contacts
        .iter()
        .enumerate()
        .map(|(c, &(_, gap))| (0..nodes).map(|n| gap - w[n * m + c]).collect())
        .collect();
    contact_reports(contacts, &forces, &displacements)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lcp_states_give_each_contact_its_own_displacements_and_forces() {
        // Two contacts (gaps 0.5 and 0.3), two nodes, time-major: w = (w00, w01, w10, w11).
        let w = [0.0, 0.1, 0.2, 0.3];
        let z = [4.0, 0.0, 0.0, 0.0];
        let y: Vec<f64> = w.iter().chain(&z).copied().collect();
        let r = lcp_point_contacts(&[(19, 0.5), (9, 0.3)], &y, 2);
        assert_eq!(r.len(), 2);
        // Contact 0: u = 0.5 - (0.0, 0.2), force (-4, 0).
        assert_eq!((r[0].displacement_max, r[0].displacement_min), (0.5, 0.3));
        assert_eq!((r[0].force_mean, r[0].contact_fraction), (-2.0, 0.5));
        // Contact 1: u = 0.3 - (0.1, 0.3), no force.
        assert_eq!(
            (r[1].displacement_max, r[1].displacement_min),
            (0.3 - 0.1, 0.0)
        );
        assert_eq!((r[1].force_mean, r[1].contact_fraction), (0.0, 0.0));
    }
}
