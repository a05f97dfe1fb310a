//! The `ssn` Python package's native module (`ssn._ssn`): scenes (read from files, built
//! from matrices or as the built-in rod, modified by scene keys), the runs of the command
//! line (`solve`, `sweep`, `solutions`) and stability, each with the GIL released, their
//! results with numpy arrays and the command line's JSON, and the study cases.
//!
//! Everything that decides a number is the library's or the application's: scenes are read
//! by `ssn::scene` (the same keys, defaults and messages as a scene file), the documents are
//! `ssn::json`'s, a study case is `ssn::study::run::run_case`.
//!
//! It depends on `ssn` without its `cli` feature (no commands, arguments, progress bars,
//! figures or ParaView files), because a Python scene is a scene file's text and keys and its
//! results are the program's JSON documents, so that a script and `ssn` agree to the letter.

mod convert;
mod errors;
mod model;
mod results;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use semismooth_contact::matrix_market::{matrix_market_text, parse_matrix};
use semismooth_contact::model::SparseMatrix;
use ssn::scene::Override;
use ssn::source::SceneSource;
use ssn::study::{Case, RunKind};
use ssn::work::Workload;

use convert::{python_json, python_value, toml_value};
use errors::{bad_input, bad_type, run_failure, RunFailure};
use results::{FrequencyResponse, Solution, SolutionSet, Stability};

/// The path of a scene built in Python from matrices (its `[model]` file names are keys of
/// the matrices held in memory).
const MATRICES_PATH: &str = "<matrices>";

/// A scene: what `ssn` reads from a scene file, with the values set by `with_values`.
///
/// Build one with `Scene.from_file(path)`, `Scene.from_toml(text)`, `Scene.rod(...)` or
/// `Scene.from_matrices(...)`; `scene.with_values({"contact.gap": 0.3})` returns a
/// modified copy (the keys of `ssn solve --set`). Scenes are immutable and picklable.
#[pyclass(module = "ssn", frozen)]
#[derive(Clone)]
pub struct Scene {
    pub(crate) source: SceneSource,
}

impl Scene {
    /// A scene from its source, validated now (so that a bad one raises where it is made).
    fn checked(source: SceneSource) -> PyResult<Scene> {
        source.scene().map_err(bad_input)?;
        Ok(Scene { source })
    }

    /// The overrides of a `{key: value}` dict, in its order; anything else than a dict is
    /// refused as `SceneTypeError`.
    fn overrides(values: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Override>> {
        let Some(values) = values else {
            return Ok(Vec::new());
        };
        let values = values.cast::<PyDict>().map_err(|_| {
            bad_type(format!(
                "values: a {}: allowed a dict from scene keys (such as forcing.amplitude) \
                 to values",
                values
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        })?;
        values
            .iter()
            .map(|(k, v)| {
                let key: String = k.extract().map_err(|_| {
                    bad_type(format!(
                        "scene key {}: allowed a str such as \"forcing.amplitude\"",
                        k.repr().map_or_else(|_| "?".into(), |r| r.to_string())
                    ))
                })?;
                let value = toml_value(&v, &key)?;
                Override::new(&key, value).map_err(bad_input)
            })
            .collect()
    }
}

#[pymethods]
impl Scene {
    /// Reads a scene file (the keys, defaults and errors of `ssn`).
    #[staticmethod]
    fn from_file(path: PathBuf) -> PyResult<Scene> {
        Scene::checked(SceneSource::from_path(&path).map_err(bad_input)?)
    }

    /// A scene from TOML text; `path` names it in messages and `[model]` file names are
    /// relative to its directory.
    #[staticmethod]
    #[pyo3(signature = (text, path = "<string>".into()))]
    fn from_toml(text: String, path: PathBuf) -> PyResult<Scene> {
        Scene::checked(SceneSource::from_text(text, path))
    }

    /// The built-in finite-element rod of the paper: `elements` elements, forced by
    /// `amplitude` (distributed load) at `omega_ratio` (units of its first natural
    /// frequency), a tip stop at `gap` (None: no contact), mass model `mass`
    /// ("consistent", "lumped", "modified"), stiffness-proportional damping `zeta`; any
    /// other scene key in `values`.
    #[staticmethod]
    #[pyo3(signature = (elements = 20, amplitude = 0.04, gap = Some(0.5), mass = "consistent".to_string(), zeta = Some(0.01), omega_ratio = 1.0, values = None))]
    #[allow(clippy::too_many_arguments)]
    fn rod(
        elements: i64,
        amplitude: f64,
        gap: Option<f64>,
        mass: String,
        zeta: Option<f64>,
        omega_ratio: f64,
        values: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Scene> {
        let mut table = toml::Table::new();
        let section = |pairs: Vec<(&str, toml::Value)>| {
            toml::Value::Table(pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect())
        };
        table.insert(
            "rod".into(),
            section(vec![("elements", elements.into()), ("mass", mass.into())]),
        );
        if let Some(zeta) = zeta {
            table.insert("damping".into(), section(vec![("zeta", zeta.into())]));
        }
        table.insert(
            "forcing".into(),
            section(vec![
                ("amplitude", amplitude.into()),
                ("omega_ratio", omega_ratio.into()),
            ]),
        );
        if let Some(gap) = gap {
            table.insert("contact".into(), section(vec![("gap", gap.into())]));
        }
        let text = toml::to_string(&table).map_err(bad_input)?;
        let source = SceneSource::from_text(text, "<rod>").with(&Scene::overrides(values)?);
        Scene::checked(source)
    }

    /// A structure of your own: mass `mass`, stiffness `stiffness` (numpy arrays or
    /// scipy.sparse matrices, N x N, symmetric, real and finite), load shape `load` (length
    /// N), contacts as `(dof, gap)` or `(dof, gap, direction)` with a 0-based `dof` and
    /// direction +1 (`u[dof] <= gap`) or -1 (`-u[dof] <= gap`), or
    /// `{"row": G_row, "gap": g}` with a row of G over one or several dofs (`"dof"` instead
    /// of `"row"`; `"friction": mu` with `"tangent": T_row` adds Coulomb friction; any
    /// other key is refused); optional damping matrix `damping`; any other scene key in `values`
    /// (`damping.zeta`, `forcing.amplitude` (default 1), `forcing.omega_ratio`,
    /// `solver.harmonics`, `output.dof` (1-based, as in scene files), ...). The checks of
    /// an imported model apply (symmetry, sizes, a nonsingular stiffness); what a scene file
    /// refuses in a contact is refused naming the contact by its 0-based index (`SceneError`,
    /// `SceneTypeError` for a value of the wrong type).
    #[staticmethod]
    #[pyo3(signature = (mass, stiffness, load, contacts = None, damping = None, values = None))]
    fn from_matrices(
        py: Python<'_>,
        mass: &Bound<'_, PyAny>,
        stiffness: &Bound<'_, PyAny>,
        load: &Bound<'_, PyAny>,
        contacts: Option<&Bound<'_, PyAny>>,
        damping: Option<&Bound<'_, PyAny>>,
        values: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Scene> {
        let helpers = py.import("ssn._convert")?;
        type Coo = (usize, usize, Vec<usize>, Vec<usize>, Vec<f64>);
        let parts: Vec<(String, Coo)> = helpers
            .call_method1("parts", (mass, stiffness, load, damping))?
            .extract()?;
        let mut matrices = BTreeMap::new();
        for (name, (rows, cols, i, j, v)) in parts {
            let triplets: Vec<faer::sparse::Triplet<usize, usize, f64>> = i
                .iter()
                .zip(&j)
                .zip(&v)
                .map(|((&i, &j), &v)| faer::sparse::Triplet::new(i, j, v))
                .collect();
            let matrix = SparseMatrix::try_new_from_triplets(rows, cols, &triplets)
                .map_err(|e| bad_input(format!("{name}: {e:?}")))?;
            matrices.insert(PathBuf::from(name), matrix);
        }
        let mut model = toml::Table::new();
        model.insert("mass".into(), "M.mtx".into());
        model.insert("stiffness".into(), "K.mtx".into());
        if damping.is_some() {
            model.insert("damping".into(), "D.mtx".into());
        }
        let mut table = toml::Table::new();
        table.insert("model".into(), toml::Value::Table(model));
        let mut forcing = toml::Table::new();
        forcing.insert("vector".into(), "f.mtx".into());
        forcing.insert("amplitude".into(), 1.0.into());
        table.insert("forcing".into(), toml::Value::Table(forcing));
        if let Some(contacts) = contacts {
            let list: Vec<Bound<'_, PyDict>> = helpers
                .call_method1("contacts", (contacts, matrices[Path::new("K.mtx")].nrows()))?
                .extract()?;
            if !list.is_empty() {
                let points: Vec<toml::Value> = list
                    .iter()
                    .map(|point| {
                        let mut p = toml::Table::new();
                        for (k, v) in point.iter() {
                            let key: String = k.extract()?;
                            let value = toml_value(&v, &format!("contact.point.{key}"))?;
                            p.insert(key, value);
                        }
                        Ok(toml::Value::Table(p))
                    })
                    .collect::<PyResult<_>>()?;
                let mut contact = toml::Table::new();
                contact.insert("point".into(), toml::Value::Array(points));
                table.insert("contact".into(), toml::Value::Table(contact));
            }
        }
        let text = toml::to_string(&table).map_err(bad_input)?;
        let mut source = SceneSource::from_text(text, MATRICES_PATH);
        source.matrices = Some(Arc::new(matrices));
        let scene = Scene::checked(source.with(&Scene::overrides(values)?))?;
        // The matrices are checked when the structure is built: build it once now.
        (scene.source.load(Workload::Solve))
            .map_err(|e| run_failure(&scene.source.path, RunFailure::Load(e)))?;
        Ok(scene)
    }

    /// A copy with scene keys set (`{"forcing.amplitude": 0.1, "contact.gap": 0.3}`: the
    /// keys of `ssn solve --set`, checked as in a scene file).
    fn with_values(&self, values: &Bound<'_, PyAny>) -> PyResult<Scene> {
        Scene::checked(self.source.with(&Scene::overrides(Some(values))?))
    }

    /// The scene keys set on this scene (by `with_values` and the constructors' `values`).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for o in &self.source.overrides {
            dict.set_item(&o.key, python_value(py, &o.value)?)?;
        }
        Ok(dict)
    }

    /// The scene's file (`<rod>`, `<matrices>` or `<string>` for scenes made in Python).
    #[getter]
    fn path(&self) -> PathBuf {
        self.source.path.clone()
    }

    /// The scene's TOML text as written (before `values`).
    #[getter]
    fn text(&self) -> String {
        self.source.text.clone()
    }

    /// The scene's title, if any.
    #[getter]
    fn title(&self) -> PyResult<Option<String>> {
        Ok(self.source.scene().map_err(bad_input)?.title)
    }

    fn __repr__(&self) -> String {
        let values = ssn::study::words(&self.source.overrides);
        format!(
            "ssn.Scene({:?}{})",
            self.source.path.display().to_string(),
            if values.is_empty() {
                String::new()
            } else {
                format!(", {values}")
            }
        )
    }

    /// Pickles as the text, path, values and in-memory matrices (as Matrix Market text,
    /// exact); unpickling checks the scene again.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let restore = py.import("ssn._pickle")?.getattr("restore_scene")?;
        let overrides: Vec<(String, String)> = self
            .source
            .overrides
            .iter()
            .map(|o| (o.key.clone(), o.value.to_string()))
            .collect();
        let matrices: Option<Vec<(String, String)>> = self.source.matrices.as_ref().map(|m| {
            m.iter()
                .map(|(p, a)| (p.display().to_string(), matrix_market_text(a)))
                .collect()
        });
        let args = PyTuple::new(
            py,
            [
                self.source.text.clone().into_pyobject(py)?.into_any(),
                self.source
                    .path
                    .display()
                    .to_string()
                    .into_pyobject(py)?
                    .into_any(),
                overrides.into_pyobject(py)?.into_any(),
                matrices.into_pyobject(py)?.into_any(),
            ],
        )?;
        Ok((restore, args))
    }

    /// Rebuilds a pickled scene (`__reduce__`).
    #[staticmethod]
    fn _restore(
        text: String,
        path: PathBuf,
        overrides: Vec<(String, String)>,
        matrices: Option<Vec<(String, String)>>,
    ) -> PyResult<Scene> {
        let mut source = SceneSource::from_text(text, path);
        for (key, value) in overrides {
            source
                .overrides
                .push(Override::new(&key, ssn::scene::parse_value(&value)).map_err(bad_input)?);
        }
        if let Some(matrices) = matrices {
            let mut map = BTreeMap::new();
            for (name, text) in matrices {
                let matrix = parse_matrix(&text, Path::new(&name)).map_err(bad_input)?;
                map.insert(PathBuf::from(name), matrix);
            }
            source.matrices = Some(Arc::new(map));
        }
        Scene::checked(source)
    }
}

/// Solves the scene at its forcing frequency (`ssn solve`), from zero; the GIL is released
/// while it runs. Not converging is not an error: see `Solution.converged`.
#[pyfunction]
fn solve(py: Python<'_>, scene: &Scene) -> PyResult<Solution> {
    let (solution, structure) = detached(py, scene, Workload::Solve, |loaded| {
        let settings = &loaded.scene.solver;
        let solution = semismooth_contact::solve(&loaded.structure, loaded.omega, settings, None)?;
        Ok((solution, loaded.structure))
    })?;
    Ok(Solution::new(&scene.source.path, &solution, &structure))
}

/// The frequency response over the scene's `[sweep]` (`ssn sweep`), with the stability of
/// every point; the GIL is released while it runs.
#[pyfunction]
fn sweep(py: Python<'_>, scene: &Scene) -> PyResult<FrequencyResponse> {
    let response = detached(py, scene, Workload::Branch, |loaded| {
        let settings = loaded.scene.sweep.as_ref().ok_or(
            "no [sweep] section: add omega_ratio_from and omega_ratio_to (units of omega_1)",
        )?;
        Ok(semismooth_contact::sweep::frequency_response(
            &loaded.structure,
            &loaded.scene.solver,
            settings,
            None,
        )?)
    })?;
    Ok(FrequencyResponse::new(&response))
}

/// Every periodic solution at the scene's frequency with its stability (`ssn solutions`);
/// the GIL is released while it runs.
#[pyfunction]
fn solutions(py: Python<'_>, scene: &Scene) -> PyResult<SolutionSet> {
    let set = detached(py, scene, Workload::Branch, |loaded| {
        Ok(semismooth_contact::solutions::find_solutions(
            &loaded.structure,
            loaded.omega,
            &loaded.scene.solver,
            loaded.scene.sweep.as_ref(),
        )?)
    })?;
    Ok(SolutionSet::new(&set))
}

/// The backbone of the scene's `[modes]` (`ssn modes`) as the document of `ssn modes
/// --json` (a dict); the GIL is released while it runs.
#[pyfunction]
fn modes<'py>(py: Python<'py>, scene: &Scene) -> PyResult<Bound<'py, PyAny>> {
    let doc = detached(py, scene, Workload::Branch, |loaded| {
        let started = std::time::Instant::now();
        let branch =
            ssn::modes::run(&loaded.scene, &loaded.structure).map_err(RunFailure::Input)?;
        let seconds = started.elapsed().as_secs_f64();
        Ok(ssn::modes::document(
            &loaded.scene,
            &branch,
            loaded.structure.omega_1,
            seconds,
        ))
    })?;
    to_dict(py, &doc)
}

/// The Floquet stability of the harmonic-balance solution at the scene's frequency (the
/// solve of `solve`, then its monodromy; a method other than SSN-HB or penalty HB is a
/// `SceneError`, a solve that did not converge a `NotConvergedError`); the GIL is released
/// while it runs.
#[pyfunction]
fn stability(py: Python<'_>, scene: &Scene) -> PyResult<Stability> {
    let (solution, stability) = detached(py, scene, Workload::Solve, |loaded| {
        let settings = &loaded.scene.solver;
        if !settings.method.is_harmonic_balance() {
            return Err(RunFailure::Input(format!(
                "stability needs a harmonic-balance method: allowed solver.method = \
                 \"ssn-hb\" or \"penalty-hb\", not \"{}\"",
                settings.method.name()
            )));
        }
        let solution = semismooth_contact::solve(&loaded.structure, loaded.omega, settings, None)?;
        if !solution.converged() {
            return Err(RunFailure::NotConverged {
                termination: solution.termination.to_string(),
                iterations: solution.iterations,
                residual_norm: solution.residual_norm,
            });
        }
        // The whole unknown vector of the method (displacements, and the contact
        // multipliers of SSN-HB): the contact phases are read from it.
        let stability =
            semismooth_contact::stability::solution_stability(&loaded.structure.model, &solution)
                .map_err(semismooth_contact::Error::from)?;
        Ok((solution, stability))
    })?;
    Ok(Stability::new(&solution, &stability))
}

/// Loads `scene` for `workload` and runs `run` on it with the GIL released; a failure is
/// raised as the exception of its kind, its message naming the scene file (as the command
/// line's).
fn detached<T: Send>(
    py: Python<'_>,
    scene: &Scene,
    workload: Workload,
    run: impl FnOnce(ssn::load::Loaded) -> Result<T, RunFailure> + Send,
) -> PyResult<T> {
    let source = scene.source.clone();
    py.detach(move || -> Result<T, RunFailure> {
        let loaded = source.load(workload).map_err(RunFailure::Load)?;
        run(loaded)
    })
    .map_err(|failure| run_failure(&scene.source.path, failure))
}

/// Runs case `index` of a study (`values`: the scene keys it sets, in order) as `run`
/// ("solve", "sweep", "solutions"); returns the record of `ssn study` as JSON text. The GIL
/// is released while it runs.
#[pyfunction]
fn run_case(
    py: Python<'_>,
    scene: &Scene,
    index: usize,
    values: &Bound<'_, PyAny>,
    run: &str,
) -> PyResult<String> {
    let kind = RunKind::from_name(run).ok_or_else(|| {
        bad_input(format!(
            "invalid run {run:?}: allowed \"solve\", \"sweep\" or \"solutions\""
        ))
    })?;
    let case = Case {
        index,
        values: Scene::overrides(Some(values))?,
    };
    let source = scene.source.clone();
    let record = py.detach(move || ssn::study::run::run_case(&source, &case, kind));
    Ok(record.to_string())
}

/// The results table of study records (JSON text of a list of records, as `run_case`
/// returns them) as `[(column, [cells])]`, the table of `ssn study` (`keys`: the varied
/// keys in column order).
#[pyfunction]
fn study_table<'py>(
    py: Python<'py>,
    run: &str,
    keys: Vec<String>,
    records: &str,
) -> PyResult<Bound<'py, PyList>> {
    use ssn::study::table::{Cell, Table};
    let kind = RunKind::from_name(run).ok_or_else(|| bad_input(format!("invalid run {run:?}")))?;
    let records: Vec<serde_json::Value> = serde_json::from_str(records).map_err(bad_input)?;
    let table = Table::from_records(kind, &keys, &records);
    let columns = PyList::empty(py);
    for column in &table.columns {
        let cells = PyList::empty(py);
        for cell in &column.cells {
            match cell {
                Cell::Null => cells.append(py.None())?,
                Cell::Int(i) => cells.append(*i)?,
                Cell::Float(f) => cells.append(*f)?,
                Cell::Bool(b) => cells.append(*b)?,
                Cell::Text(s) => cells.append(s)?,
            }
        }
        columns.append((column.name.clone(), cells))?;
    }
    Ok(columns)
}

/// The CSV text of the table of `study_table`'s arguments (the `results.csv` of
/// `ssn study`).
#[pyfunction]
fn study_csv(run: &str, keys: Vec<String>, records: &str) -> PyResult<String> {
    let kind = RunKind::from_name(run).ok_or_else(|| bad_input(format!("invalid run {run:?}")))?;
    let records: Vec<serde_json::Value> = serde_json::from_str(records).map_err(bad_input)?;
    Ok(ssn::study::table::Table::from_records(kind, &keys, &records).csv())
}

/// The scene keys of each case of a study file (`ssn study`'s cases, checked against
/// `scene`): `(run, keys, [[(key, value)]])`.
#[pyfunction]
fn study_cases<'py>(
    py: Python<'py>,
    scene: &Scene,
    path: PathBuf,
) -> PyResult<(String, Vec<String>, Bound<'py, PyList>)> {
    let study = ssn::study::Study::from_path(&path, &scene.source).map_err(bad_input)?;
    let cases = PyList::empty(py);
    for case in &study.cases {
        let dict = PyDict::new(py);
        for o in &case.values {
            dict.set_item(&o.key, python_value(py, &o.value)?)?;
        }
        cases.append(dict)?;
    }
    Ok((study.run.name().to_string(), study.keys.clone(), cases))
}

/// Threads of the linear algebra inside one process: 1 runs every solve on the calling
/// thread (what a worker process of a study should do, so that workers do not compete for
/// the cores and every case's arithmetic is that of a serial run); 0 uses every core.
/// Returns the previous count (0 for every core).
#[pyfunction]
fn limit_threads(threads: usize) -> usize {
    let previous = match faer::get_global_parallelism() {
        faer::Par::Seq => 1,
        faer::Par::Rayon(n) => n.get(),
    };
    faer::set_global_parallelism(match threads {
        1 => faer::Par::Seq,
        n => faer::Par::rayon(n),
    });
    previous
}

/// The JSON document of a result as Python objects (`to_dict`).
pub(crate) fn to_dict<'py>(
    py: Python<'py>,
    doc: &serde_json::Value,
) -> PyResult<Bound<'py, PyAny>> {
    python_json(py, doc)
}

#[pymodule]
fn _ssn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Solution>()?;
    m.add_class::<FrequencyResponse>()?;
    m.add_class::<SolutionSet>()?;
    m.add_class::<Stability>()?;
    m.add_class::<model::Model>()?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(solutions, m)?)?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(run_case, m)?)?;
    m.add_function(wrap_pyfunction!(study_table, m)?)?;
    m.add_function(wrap_pyfunction!(study_csv, m)?)?;
    m.add_function(wrap_pyfunction!(study_cases, m)?)?;
    m.add_function(wrap_pyfunction!(limit_threads, m)?)?;
    m.add_function(wrap_pyfunction!(results::_restore_result, m)?)?;
    Ok(())
}
