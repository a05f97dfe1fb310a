//! Every 3-D frictional contact of every point of an SSN-HB branch
//! ([`ResponsePoint::frictional_contacts`]): the numbers `ssn solve` reports for one
//! solution ([`FrictionalContactSummary`]), reconstructed on
//! [`FrequencyResponse::output_points`] equally spaced times. Unlike the 1-D contacts'
//! reports they depend on the frequency (slip velocities, energy per period), so the
//! problem is moved to each point's `omega` before its reconstruction.

use crate::hb::{FrictionalContactSummary, SsnHb};
use crate::model::Structure;
use crate::settings::{Method, SolverSettings};
use crate::solve::{hb_options, RunError};

use super::{FrequencyResponse, ResponsePoint, StateRecovery};

/// Sets the 3-D frictional contacts' summaries of each point of an SSN-HB `response`
/// (nothing for other methods or without 3-D contacts).
pub(super) fn set_frictional_summaries(
    structure: &Structure,
    settings: &SolverSettings,
    response: &mut FrequencyResponse,
) -> Result<(), RunError> {
    let model = &structure.model;
    let count = model.frictional_contacts.len();
    if count == 0 || settings.method != Method::SsnHb {
        return Ok(());
    }
    let points = response.output_points;
    let mut current: Option<((usize, usize), SsnHb)> = None;
    let mut summaries = Vec::with_capacity(response.points.len());
    let mut states = StateRecovery::new(structure, settings, response);
    for (i, ResponsePoint { omega, .. }) in response.points.iter().enumerate() {
        let state = &*states.state(i)?;
        let at = response.point_settings(settings, i);
        let key = (at.harmonics, at.time_samples);
        if current.as_ref().is_none_or(|(k, _)| *k != key) {
            current = Some((key, SsnHb::new(model, *omega, &hb_options(&at))?));
        }
        let (_, problem) = current.as_mut().expect("built above");
        problem.set_omega(*omega)?;
        let point: Vec<FrictionalContactSummary> = (0..count)
            .map(|p| {
                Ok(problem
                    .frictional_contact_report(state, p, points)?
                    .summary())
            })
            .collect::<Result<_, RunError>>()?;
        summaries.push(point);
    }
    for (point, summary) in response.points.iter_mut().zip(summaries) {
        point.frictional_contacts = summary;
    }
    Ok(())
}
