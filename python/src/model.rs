//! `Model`: the structure a scene builds, its natural frequencies, and its reduction by
//! component mode synthesis (Craig–Bampton or MacNeal's massless boundary), through the
//! library (`semismooth_contact::reduction`), not the `ssn` program.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use semismooth_contact::import::LANCZOS_MIN_DOFS;
use semismooth_contact::model::Structure;
use semismooth_contact::reduction::{
    boundary_dofs, craig_bampton, lowest_frequencies, massless_boundary, CraigBampton, ModeCount,
    ReductionError,
};
use semismooth_contact::rod::natural_frequencies;
use ssn::work::Workload;

use crate::errors::bad_input;
use crate::Scene;

/// A structure: mass, stiffness, damping, contacts, load and observed dof, as a scene builds
/// it (its `[reduction]` not applied: that is `reduce`).
///
/// `Model.from_scene(scene)`; `model.dofs`, `model.omega_1`, `model.frequencies(count)`;
/// `model.reduce(method="craig-bampton", modes=None, cutoff=None)` returns the reduced
/// model onto the contact, friction, observed and loaded dofs.
#[pyclass(module = "ssn", frozen)]
pub struct Model {
    structure: Structure,
}

#[pymethods]
impl Model {
    /// The structure `scene` builds (the GIL released while its files are read).
    #[staticmethod]
    fn from_scene(py: Python<'_>, scene: &Scene) -> PyResult<Model> {
        let structure = crate::detached(py, scene, Workload::Check, |loaded| Ok(loaded.structure))?;
        Ok(Model { structure })
    }

    /// The number of dofs.
    #[getter]
    fn dofs(&self) -> usize {
        self.structure.model.dofs()
    }

    /// The lowest natural frequency (rad per unit time) of the structure as built.
    #[getter]
    fn omega_1(&self) -> f64 {
        self.structure.omega_1
    }

    /// The `count` lowest finite natural frequencies of `(K, M)`, ascending (shift-invert
    /// Lanczos above 2000 dofs, subspace iteration below); the GIL released.
    fn frequencies(&self, py: Python<'_>, count: usize) -> PyResult<Vec<f64>> {
        let model = &self.structure.model;
        py.detach(|| {
            if model.dofs() > LANCZOS_MIN_DOFS {
                lowest_frequencies(model, count).map_err(|e| e.to_string())
            } else {
                natural_frequencies(model, count).map_err(|e| e.to_string())
            }
        })
        .map_err(|e| PyValueError::new_err(format!("frequencies({count}): {e}")))
    }

    /// The model reduced onto its boundary (contact, friction, observed and loaded dofs):
    /// `method` `"craig-bampton"` (fixed-interface modes, the boundary keeps its mass) or
    /// `"massless-boundary"` (free-interface modes and residual flexibility, MacNeal), the
    /// modes by count (`modes`) or below the angular frequency `cutoff`. The reduced
    /// model's `omega_1` is its own.
    #[pyo3(signature = (method = "craig-bampton", modes = None, cutoff = None))]
    fn reduce(
        &self,
        py: Python<'_>,
        method: &str,
        modes: Option<usize>,
        cutoff: Option<f64>,
    ) -> PyResult<Model> {
        let count = match (modes, cutoff) {
            (Some(n), None) => ModeCount::Count(n),
            (None, Some(w)) if w.is_finite() && w > 0.0 => ModeCount::Below(w),
            _ => {
                return Err(bad_input(format!(
                    "modes = {modes:?}, cutoff = {cutoff:?}: allowed one of them, `modes` a \
                     count or `cutoff` a finite angular frequency > 0"
                )))
            }
        };
        type Reduction =
            fn(&Structure, &[usize], ModeCount) -> Result<CraigBampton, ReductionError>;
        let reduce: Reduction = match method {
            "craig-bampton" => craig_bampton,
            "massless-boundary" => massless_boundary,
            other => {
                return Err(bad_input(format!(
                    "method {other:?}: allowed \"craig-bampton\" or \"massless-boundary\""
                )))
            }
        };
        let full = &self.structure;
        let reduced = py
            .detach(|| reduce(full, &boundary_dofs(full, &[]), count))
            .map_err(|e| PyValueError::new_err(format!("reduce: {e}")))?;
        Ok(Model {
            structure: reduced.structure,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(dofs={}, omega_1={:e})",
            self.structure.model.dofs(),
            self.structure.omega_1
        )
    }
}
