//! `[reduction]`: the structure reduced by component mode synthesis before it is solved
//! (module `semismooth_contact::reduction`). `method = "craig-bampton"` keeps the contact,
//! friction, observed and loaded dofs and the fixed-interface modes of the rest: `modes = N`
//! of them, or those below `cutoff_ratio` times the highest harmonic's frequency
//! (`H omega`), not both. `method = "massless-boundary"` keeps the same dofs massless
//! beside free-interface modes (MacNeal's residual flexibility). `modal_damping = zeta` replaces the reduced model's damping by
//! modal damping of ratio `zeta` on each of its modes.

use semismooth_contact::reduction::ModeCount;

use super::check::Check;
use super::*;

/// Largest `[reduction] modes`.
pub const MAX_REDUCTION_MODES: usize = 100_000;

/// How many fixed-interface modes a reduction keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeSelection {
    /// `modes = N`: the lowest `N`.
    Count(usize),
    /// `cutoff_ratio = r`: every mode below `r H omega`.
    CutoffRatio(f64),
}

/// Which reduction: `method = "craig-bampton"` or `"massless-boundary"` (MacNeal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReductionMethod {
    /// Fixed-interface modes and static constraint modes; the boundary keeps its mass.
    CraigBampton,
    /// Free-interface modes and the boundary's residual flexibility; a massless boundary.
    MasslessBoundary,
}

impl ReductionMethod {
    /// The scene's name of the method.
    pub fn name(self) -> &'static str {
        match self {
            Self::CraigBampton => "craig-bampton",
            Self::MasslessBoundary => "massless-boundary",
        }
    }
}

/// A validated `[reduction]` section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReductionSpec {
    /// The method.
    pub method: ReductionMethod,
    /// The interior modes kept.
    pub modes: ModeSelection,
    /// `modal_damping = zeta`: the reduced model's damping is modal damping of this ratio
    /// (`semismooth_contact::reduction::modal_damping`) instead of the projected one.
    pub modal_damping: Option<f64>,
}

impl ReductionSpec {
    /// The modes to keep at the forcing frequency `omega` with `harmonics` harmonics.
    pub fn mode_count(&self, omega: f64, harmonics: usize) -> ModeCount {
        match self.modes {
            ModeSelection::Count(n) => ModeCount::Count(n),
            ModeSelection::CutoffRatio(r) => ModeCount::Below(r * harmonics as f64 * omega),
        }
    }
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
pub(super) enum RawReductionMethod {
    CraigBampton,
    MasslessBoundary,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawReduction {
    method: RawReductionMethod,
    modes: Option<i64>,
    cutoff_ratio: Option<f64>,
    modal_damping: Option<f64>,
}

impl Check<'_> {
    /// `[reduction]`: the method and either `modes` or `cutoff_ratio`.
    pub(super) fn reduction(&self, r: &RawReduction) -> Result<ReductionSpec, SceneError> {
        let modes = match (r.modes, r.cutoff_ratio) {
            (Some(n), None) => {
                ModeSelection::Count(self.count("reduction.modes", n, 1, MAX_REDUCTION_MODES)?)
            }
            (None, Some(c)) => {
                ModeSelection::CutoffRatio(self.positive("reduction.cutoff_ratio", c)?)
            }
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    "reduction.cutoff_ratio",
                    "given together with `modes`",
                    "either `modes` (a count) or `cutoff_ratio` (times the highest \
                     harmonic's frequency)",
                ))
            }
            (None, None) => {
                return Err(self.invalid(
                    "reduction.modes",
                    "missing",
                    "`modes` (the fixed-interface modes kept, >= 1) or `cutoff_ratio` (the \
                     modes below this many times the highest harmonic's frequency)",
                ))
            }
        };
        let modal_damping = (r.modal_damping)
            .map(|z| self.non_negative("reduction.modal_damping", z))
            .transpose()?;
        let method = match r.method {
            RawReductionMethod::CraigBampton => ReductionMethod::CraigBampton,
            RawReductionMethod::MasslessBoundary => ReductionMethod::MasslessBoundary,
        };
        Ok(ReductionSpec {
            method,
            modes,
            modal_damping,
        })
    }
}
