//! Results as Python objects: numpy arrays of the curves and the command line's JSON
//! document (`to_dict()`); picklable (the document and the arrays).

use std::path::Path;

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use serde_json::{json, Value};

use semismooth_contact::model::{CyclicCoupling, Structure};
use semismooth_contact::solutions::SolutionSet as LibSolutionSet;
use semismooth_contact::stability::Stability as LibStability;
use semismooth_contact::sweep::FrequencyResponse as LibResponse;

use crate::errors::bad_input;

/// A result's document and arrays (name, shape, values in row-major order).
#[derive(Debug, Clone)]
pub struct Stored {
    doc: Value,
    arrays: Vec<(String, Vec<usize>, Vec<f64>)>,
}

impl Stored {
    fn array<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let (_, shape, values) = self
            .arrays
            .iter()
            .find(|(n, _, _)| n == name)
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_string()))?;
        let flat = PyArray1::from_slice(py, values);
        Ok(match shape.as_slice() {
            [_] => flat.into_any(),
            dims => flat.reshape(dims.to_vec())?.into_any(),
        })
    }

    fn field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        crate::to_dict(py, &self.doc[name])
    }

    fn reduce<'py>(
        &self,
        py: Python<'py>,
        kind: &str,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let restore = py.import("ssn._pickle")?.getattr("restore_result")?;
        let args = PyTuple::new(
            py,
            [
                kind.into_pyobject(py)?.into_any(),
                self.doc.to_string().into_pyobject(py)?.into_any(),
                self.arrays.clone().into_pyobject(py)?.into_any(),
            ],
        )?;
        Ok((restore, args))
    }
}

/// Rows as a row-major array `(rows, columns)`.
fn matrix<R: AsRef<[f64]>>(name: &str, rows: &[R]) -> (String, Vec<usize>, Vec<f64>) {
    // Rows of different lengths (a branch whose harmonics change from point to point)
    // are padded with NaN to the longest.
    let columns = rows.iter().map(|r| r.as_ref().len()).max().unwrap_or(0);
    let values: Vec<f64> = rows
        .iter()
        .flat_map(|r| {
            r.as_ref()
                .iter()
                .copied()
                .chain(std::iter::repeat(f64::NAN))
                .take(columns)
        })
        .collect();
    (name.to_string(), vec![rows.len(), columns], values)
}

fn vector(name: &str, values: &[f64]) -> (String, Vec<usize>, Vec<f64>) {
    (name.to_string(), vec![values.len()], values.to_vec())
}

/// The `#[pymethods]` of a result class: `to_dict`, `converged`, pickling, and `$rest`.
macro_rules! result_methods {
    ($ty:ident, $kind:literal, { $($rest:tt)* }) => {
        #[pymethods]
        impl $ty {
            /// The command line's JSON document of this result, as `json.loads` gives it.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                crate::to_dict(py, &self.stored.doc)
            }

            /// Whether the run converged (the command line's exit code 0).
            #[getter]
            fn converged(&self) -> bool {
                self.converged
            }

            fn __reduce__<'py>(
                &self,
                py: Python<'py>,
            ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
                self.stored.reduce(py, $kind)
            }

            $($rest)*
        }
    };
}

/// One periodic response (`ssn.solve`): the observed dof and the contact forces over one
/// period, the unknowns, and the JSON of `ssn solve --json` (`to_dict()`).
#[pyclass(module = "ssn", frozen)]
pub struct Solution {
    stored: Stored,
    converged: bool,
}

impl Solution {
    pub fn new(
        scene: &Path,
        s: &semismooth_contact::solve::Solution,
        structure: &Structure,
    ) -> Solution {
        let mut doc = ssn::json::solution_json(scene, s);
        let mut arrays = vec![
            vector("times", &s.times),
            vector("displacement", &s.observed),
            matrix("contact_forces", &s.contact_forces),
            vector("state", &s.state),
            vector("observed_dof", &[structure.observed_dof as f64]),
        ];
        if let Some(amplitudes) = ssn::json::blade_amplitudes(structure, s) {
            let values: Vec<f64> = (amplitudes.as_array().into_iter().flatten())
                .map(|a| a.as_f64().unwrap_or(f64::NAN))
                .collect();
            arrays.push(vector("blade_amplitudes", &values));
            arrays.extend(sector_recovery(structure, s));
            doc["blade_amplitudes"] = amplitudes;
        }
        Solution {
            converged: s.converged(),
            stored: Stored { arrays, doc },
        }
    }

    /// The values of the stored array `name` (`None` when this solution has none).
    fn stored_array(&self, name: &str) -> Option<&[f64]> {
        (self.stored.arrays.iter())
            .find(|(n, _, _)| n == name)
            .map(|(_, _, v)| v.as_slice())
    }
}

/// What a cyclic sector's solution keeps to give any blade's time series on request: the
/// observed dof's harmonic coefficients `[u_0, a_1, b_1, ...]` and `[N, phi]`.
fn sector_recovery(
    structure: &Structure,
    s: &semismooth_contact::solve::Solution,
) -> Vec<(String, Vec<usize>, Vec<f64>)> {
    let (Some(coupling), Some(harmonics)) = (structure.model.cyclic.as_ref(), s.harmonics) else {
        return Vec::new();
    };
    let (n, dof) = (structure.model.dofs(), structure.observed_dof);
    let coefficients: Option<Vec<f64>> = (0..2 * harmonics + 1)
        .map(|j| s.state.get(j * n + dof).copied())
        .collect();
    coefficients.map_or_else(Vec::new, |c| {
        vec![
            vector("observed_coefficients", &c),
            vector("cyclic", &[coupling.sectors as f64, coupling.phase_step]),
        ]
    })
}

result_methods!(Solution, "Solution", {
    /// Sample times over one period.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "times")
    }

    /// The dof (0-based) whose displacement `displacement` is (`[output] dof`).
    #[getter]
    fn observed_dof(&self) -> usize {
        self.stored
            .arrays
            .iter()
            .find(|(n, _, _)| n == "observed_dof")
            .map_or(0, |(_, _, v)| v[0] as usize)
    }

    /// Displacement of the observed dof at `times` (`tip_*` of the JSON).
    #[getter]
    fn displacement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "displacement")
    }

    /// Contact forces at `times`, one row per contact (`lambda <= 0`).
    #[getter]
    fn contact_forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "contact_forces")
    }

    /// The method's unknowns (harmonic balance: the coefficients `[U; Lambda]`, harmonic
    /// major, in the basis `1, cos, sin, ..., cos H, sin H`).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "state")
    }

    /// Per-contact quantities (the JSON's `contacts`).
    #[getter]
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.field(py, "contacts")
    }

    /// Per-friction-point quantities (the JSON's `friction`: stick fraction, force
    /// amplitude, and the tangential force and slip velocity over the period).
    #[getter]
    fn friction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.field(py, "friction")
    }

    /// Why the solver stopped (`converged`, `max-iterations`, ...).
    #[getter]
    fn termination(&self) -> String {
        self.stored.doc["termination"]
            .as_str()
            .unwrap_or_default()
            .to_string()
    }

    /// Why the solver stopped, as an `ssn.Termination` member (the first word of
    /// `termination`).
    #[getter]
    fn termination_kind<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("ssn._termination")?
            .getattr("Termination")?
            .call_method1("of", (self.termination(),))
    }

    /// Newton iterations (or Lemke pivots, periods marched).
    #[getter]
    fn iterations(&self) -> u64 {
        self.stored.doc["iterations"].as_u64().unwrap_or(0)
    }

    /// Last residual norm (None when not finite).
    #[getter]
    fn residual_norm(&self) -> Option<f64> {
        self.stored.doc["residual_norm"].as_f64()
    }

    /// Forcing frequency (rad per unit time).
    #[getter]
    fn omega(&self) -> f64 {
        self.stored.doc["omega"].as_f64().unwrap_or(f64::NAN)
    }

    /// A cyclic sector's solve: the observed dof's amplitude `max_t |u|` in every sector of
    /// the full disk (the JSON's `blade_amplitudes`); `None` for any other scene.
    #[getter]
    fn blade_amplitudes<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        if self.stored_array("blade_amplitudes").is_none() {
            return Ok(None);
        }
        self.stored.array(py, "blade_amplitudes").map(Some)
    }

    /// A cyclic sector's solve: the observed dof's displacement in sector `blade` of the
    /// full disk at `times`, `u_blade(t) = u_0(t - blade EO T / N)` from the harmonics of
    /// `displacement` (`ValueError` for another scene or a blade outside `0..N`).
    fn blade_displacement<'py>(
        &self,
        py: Python<'py>,
        blade: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (Some(cyclic), Some(coefficients), Some(times)) = (
            self.stored_array("cyclic"),
            self.stored_array("observed_coefficients"),
            self.stored_array("times"),
        ) else {
            return Err(bad_input(
                "blade_displacement: the solution is not a [cyclic] sector's harmonic balance",
            ));
        };
        let sectors = cyclic[0] as usize;
        if blade >= sectors {
            return Err(bad_input(format!(
                "blade_displacement: blade {blade}: allowed 0..{sectors} (the disk's sectors)"
            )));
        }
        let coupling = CyclicCoupling::new(cyclic[1], sectors, Vec::new());
        let omega = self.omega();
        let phases: Vec<f64> = times.iter().map(|t| omega * t).collect();
        let series = coupling.sector_series(coefficients, blade, &phases);
        Ok(PyArray1::from_vec(py, series).into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "ssn.Solution(converged={}, termination={:?}, iterations={}, tip_min={}, tip_max={})",
            self.converged,
            self.termination(),
            self.iterations(),
            self.stored.doc["tip_min"],
            self.stored.doc["tip_max"]
        )
    }
});

/// A frequency response (`ssn.sweep`): one entry per branch point, and the JSON of
/// `ssn sweep --json` (`to_dict()`).
#[pyclass(module = "ssn", frozen)]
pub struct FrequencyResponse {
    stored: Stored,
    converged: bool,
}

impl FrequencyResponse {
    pub fn new(r: &LibResponse) -> FrequencyResponse {
        let (stable, floquet) = ssn::output::stability_numbers(r);
        FrequencyResponse {
            converged: r.converged(),
            stored: Stored {
                doc: ssn::json::response_json(r),
                arrays: vec![
                    vector("omega", &r.omegas()),
                    vector("omega_ratio", &r.omega_ratio()),
                    vector("tip_max", &r.column(|p| p.observed_max)),
                    vector("tip_min", &r.column(|p| p.observed_min)),
                    vector("amplitude", &r.amplitudes()),
                    vector("stable", &stable),
                    vector("floquet_max_abs", &floquet),
                    matrix(
                        "states",
                        &r.points.iter().map(|p| &p.state).collect::<Vec<_>>(),
                    ),
                ],
            },
        }
    }
}

result_methods!(FrequencyResponse, "FrequencyResponse", {
    /// Forcing frequency of each point (rad per unit time).
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "omega")
    }

    /// Forcing frequency of each point in units of the first natural frequency.
    #[getter]
    fn omega_ratio<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "omega_ratio")
    }

    /// `max_t u(t)` of the observed dof at each point.
    #[getter]
    fn tip_max<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "tip_max")
    }

    /// `min_t u(t)` of the observed dof at each point.
    #[getter]
    fn tip_min<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "tip_min")
    }

    /// `max_t |u(t)|` of the observed dof at each point.
    #[getter]
    fn amplitude<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "amplitude")
    }

    /// Stability of each point: 1 stable, 0 unstable, NaN undecided.
    #[getter]
    fn stable<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "stable")
    }

    /// Largest Floquet multiplier modulus of each point (NaN undecided).
    #[getter]
    fn floquet_max_abs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "floquet_max_abs")
    }

    /// The unknowns at each point, one row per point (where the harmonics change from point
    /// to point, `to_dict()["harmonics"]`, each row is padded with NaN to the longest).
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "states")
    }

    /// Frequencies (rad per unit time) where the branch turns back.
    #[getter]
    fn folds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.field(py, "folds")
    }

    fn __len__(&self) -> usize {
        self.stored.doc["points"].as_u64().unwrap_or(0) as usize
    }

    fn __repr__(&self) -> String {
        format!(
            "ssn.FrequencyResponse(points={}, converged={}, folds={})",
            self.__len__(),
            self.converged,
            self.stored.doc["folds"]
        )
    }
});

/// Every periodic solution at one frequency (`ssn.solutions`), and the JSON of
/// `ssn solutions --json` (`to_dict()`).
#[pyclass(module = "ssn", frozen)]
pub struct SolutionSet {
    stored: Stored,
    converged: bool,
}

impl SolutionSet {
    pub fn new(set: &LibSolutionSet) -> SolutionSet {
        let times: Vec<Vec<f64>> = set
            .solutions
            .iter()
            .map(|s| s.solution.times.clone())
            .collect();
        let tips: Vec<Vec<f64>> = set
            .solutions
            .iter()
            .map(|s| s.solution.observed.clone())
            .collect();
        let doc = ssn::solutions::document(set);
        SolutionSet {
            converged: doc["converged"] == true,
            stored: Stored {
                doc,
                arrays: vec![matrix("times", &times), matrix("displacements", &tips)],
            },
        }
    }
}

result_methods!(SolutionSet, "SolutionSet", {
    /// Each solution (the JSON's `solutions`: extremes, stability, state).
    #[getter]
    fn solutions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.field(py, "solutions")
    }

    /// Sample times of each solution, one row per solution.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "times")
    }

    /// The observed dof over one period, one row per solution.
    #[getter]
    fn displacements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.stored.array(py, "displacements")
    }

    fn __len__(&self) -> usize {
        self.stored.doc["solutions"].as_array().map_or(0, Vec::len)
    }

    fn __repr__(&self) -> String {
        format!("ssn.SolutionSet(solutions={})", self.__len__())
    }
});

/// The Floquet stability of the solution at the scene's frequency (`ssn.stability`).
#[pyclass(module = "ssn", frozen)]
pub struct Stability {
    stored: Stored,
    converged: bool,
}

impl Stability {
    pub fn new(solution: &semismooth_contact::solve::Solution, st: &LibStability) -> Stability {
        let values = st.multipliers.values();
        let doc = json!({
            "stable": st.stable,
            "floquet_max_abs": st.floquet_max_abs,
            "stability_note": st.undecided.as_ref().map(ssn::words::undecided),
            "phases": st.phases,
            "closings": st.closings,
            "omega": solution.omega,
            "omega_ratio": solution.omega / solution.omega_1,
            "solution_converged": solution.converged(),
        });
        Stability {
            converged: solution.converged(),
            stored: Stored {
                doc,
                arrays: vec![
                    vector(
                        "multipliers_re",
                        &values.iter().map(|v| v.0).collect::<Vec<_>>(),
                    ),
                    vector(
                        "multipliers_im",
                        &values.iter().map(|v| v.1).collect::<Vec<_>>(),
                    ),
                ],
            },
        }
    }
}

result_methods!(Stability, "Stability", {
    /// True stable, False unstable, None undecided (see `to_dict()["stability_note"]`).
    #[getter]
    fn stable(&self) -> Option<bool> {
        self.stored.doc["stable"].as_bool()
    }

    /// Largest multiplier modulus (None when undecided).
    #[getter]
    fn floquet_max_abs(&self) -> Option<f64> {
        self.stored.doc["floquet_max_abs"].as_f64()
    }

    /// The Floquet multipliers (complex), by decreasing modulus.
    #[getter]
    fn multipliers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let re = self.stored.array(py, "multipliers_re")?;
        let im = self.stored.array(py, "multipliers_im")?;
        let j = pyo3::types::PyComplex::from_doubles(py, 0.0, 1.0);
        re.add(im.mul(j)?)
    }

    fn __repr__(&self) -> String {
        format!(
            "ssn.Stability(stable={}, floquet_max_abs={})",
            self.stored.doc["stable"], self.stored.doc["floquet_max_abs"]
        )
    }
});

/// Rebuilds a pickled result (`__reduce__`).
#[pyfunction]
pub fn _restore_result(
    py: Python<'_>,
    kind: &str,
    doc: &str,
    arrays: Vec<(String, Vec<usize>, Vec<f64>)>,
) -> PyResult<Py<PyAny>> {
    let doc: Value = serde_json::from_str(doc)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    let flag = |key: &str| doc[key].as_bool().unwrap_or(false);
    let (converged, solution_converged) = (flag("converged"), flag("solution_converged"));
    let stored = Stored { doc, arrays };
    match kind {
        "Solution" => into_py(py, Solution { stored, converged }),
        "FrequencyResponse" => into_py(py, FrequencyResponse { stored, converged }),
        "SolutionSet" => into_py(py, SolutionSet { stored, converged }),
        "Stability" => into_py(
            py,
            Stability {
                stored,
                converged: solution_converged,
            },
        ),
        other => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "unknown result kind {other:?}"
        ))),
    }
}

/// A result class's value as a Python object.
fn into_py<T>(py: Python<'_>, value: T) -> PyResult<Py<PyAny>>
where
    T: pyo3::PyClass + Into<pyo3::PyClassInitializer<T>>,
{
    Ok(Py::new(py, value)?.into_any())
}
