//! What a sweep keeps of each branch point's state, and the full state recovered from it.
//!
//! An SSN-HB state is `[U; Lambda]`: `(2H + 1)(N + m)` numbers, of which the outputs read
//! the observed dof's and the contact rows' coefficients. At fixed `ω` the displacements
//! follow from the contact forces through the linear part alone,
//! `U = A(ω)^{-1} (F + G^T Lambda)` (one solve per harmonic, [`CondensedSsnHb::expand`]), so
//! with [`StateStorage::ContactForces`] a branch keeps `Lambda` only (`m (2H + 1)` numbers a
//! point) and [`StateRecovery`] rebuilds `[U; Lambda]` where a full state is read (contact
//! reports, stability, the peak search, period doubling, fold refinement, crossings).
//!
//! The recovered `U` solves the equations of motion exactly; the continuation's own `U`
//! solves them to the corrector's tolerance (the pseudo-arclength step moves `ω` with the
//! state, so the linear rows keep a residual `r` of second order in the last correction):
//! the two differ by `A(ω)^{-1} r`. The observed extremes, the frequencies and the folds
//! are taken from the continuation's state before it is reduced, so they do not change.

use std::borrow::Cow;

use crate::hb::{CondensedSsnHb, HbError};
use crate::model::{StructuralModel, Structure};
use crate::settings::{Method, SolverSettings};
use crate::solve::hb_options;

use super::{FrequencyResponse, StateStorage};

/// Largest difference, relative to the state's largest entry, between the branch's start
/// and its recovery for a branch to keep only the contact forces: a structural
/// mismatch (a model whose `U` is not `A^{-1} (F + G^T Lambda)`) differs by order one, the
/// corrector's residual by far less (module documentation).
const RECOVERY_CHECK: f64 = 1e-6;

/// Reduces the states of an SSN-HB branch to their contact forces as the points are
/// accepted, once the recovery reproduces the branch's start (else the branch keeps full
/// states).
pub(super) struct Compaction<'m> {
    model: &'m StructuralModel,
    settings: &'m SolverSettings,
    /// Length of `U` in `[U; Lambda]`.
    split: usize,
    /// Whether the recovery reproduced the first point (`None` before it).
    verified: Option<bool>,
}

impl<'m> Compaction<'m> {
    /// The compaction of an SSN-HB branch on `model` with `settings` whose states hold
    /// `split` displacement coefficients before the forces; `None` unless `storage` asks for
    /// it and the method is SSN-HB.
    pub(super) fn of(
        storage: StateStorage,
        model: &'m StructuralModel,
        settings: &'m SolverSettings,
        split: usize,
    ) -> Option<Self> {
        (storage == StateStorage::ContactForces && settings.method == Method::SsnHb).then_some(
            Self {
                model,
                settings,
                split,
                verified: None,
            },
        )
    }

    /// Checks the recovery on the branch's start `state` at `omega` (before the
    /// continuation allocates its workspace, so the check's factorizations do not add to
    /// the sweep's peak memory): without it the branch keeps full states.
    pub(super) fn verify(&mut self, omega: f64, state: &[f64]) {
        self.verified = Some(self.reproduces(omega, state));
    }

    /// What the branch keeps of `state`: its contact forces once [`Compaction::verify`]
    /// passed, else all of it.
    pub(super) fn keep(&self, state: Vec<f64>) -> Vec<f64> {
        if self.verified == Some(true) {
            state[self.split..].to_vec()
        } else {
            state
        }
    }

    /// Whether `[U; Lambda]` at `omega` is recovered from `Lambda` within
    /// [`RECOVERY_CHECK`].
    fn reproduces(&self, omega: f64, state: &[f64]) -> bool {
        let recovered = CondensedSsnHb::new(self.model, omega, &hb_options(self.settings))
            .and_then(|mut condensed| condensed.expand(&state[self.split.min(state.len())..]));
        let Ok(recovered) = recovered else {
            return false;
        };
        let scale = state.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        recovered.len() == state.len()
            && (recovered.iter().zip(state)).all(|(a, b)| (a - b).abs() <= RECOVERY_CHECK * scale)
    }

    /// What the branch's points hold: the contact forces once verified.
    pub(super) fn storage(&self) -> StateStorage {
        match self.verified {
            Some(true) => StateStorage::ContactForces,
            _ => StateStorage::Full,
        }
    }
}

/// The full states of a branch's points: borrowed where the branch kept them, recovered
/// from the contact forces (`U = A(ω)^{-1} (F + G^T Lambda)` at the point's `ω`, one
/// factorization of the dynamic blocks per point) where it kept only those.
pub struct StateRecovery<'r> {
    response: &'r FrequencyResponse,
    model: &'r StructuralModel,
    settings: &'r SolverSettings,
    /// The condensed problem of the last point's harmonics and samples.
    condensed: Option<((usize, usize), CondensedSsnHb)>,
}

impl<'r> StateRecovery<'r> {
    /// The recovery of `response`'s states, computed on `structure` with `settings`.
    pub fn new(
        structure: &'r Structure,
        settings: &'r SolverSettings,
        response: &'r FrequencyResponse,
    ) -> Self {
        Self {
            response,
            model: &structure.model,
            settings,
            condensed: None,
        }
    }

    /// The full state of point `i` (a [`HbError`] when its recovery fails; `i` must be a
    /// point of the branch).
    pub fn state(&mut self, i: usize) -> Result<Cow<'r, [f64]>, HbError> {
        let point = &self.response.points[i];
        if self.response.state_storage == StateStorage::Full {
            return Ok(Cow::Borrowed(&point.state));
        }
        let at = self.response.point_settings(self.settings, i);
        let key = (at.harmonics, at.time_samples);
        let condensed = match &mut self.condensed {
            Some((k, condensed)) if *k == key => {
                condensed.set_omega(point.omega)?;
                condensed
            }
            slot => {
                let built = CondensedSsnHb::new(self.model, point.omega, &hb_options(&at))?;
                &mut slot.insert((key, built)).1
            }
        };
        Ok(Cow::Owned(condensed.expand(&point.state)?))
    }
}
