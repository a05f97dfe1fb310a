//! Any scene's structure exported as a `[model]` scene (`ssn export-model`).

use semismooth_contact::matrix_market::{matrix_market_text, vector_market_text};
use semismooth_contact::model::{
    ContactRow, HarmonicLoad, NormalForce, StructuralModel, Structure,
};
use semismooth_contact::rod::FrequencySpec;
use semismooth_contact::settings::SolverSettings;

/// Name of the scene file [`export_files`] writes.
pub const EXPORTED_SCENE: &str = "scene.toml";

/// The files of a scene's structure as a `[model]` scene: `M.mtx`, `K.mtx`, `D.mtx` (when
/// damped), `f.mtx` (the load's cosine part on the forcing frequency at unit amplitude, and
/// one file for each of its other parts) and [`EXPORTED_SCENE`], whose
/// forcing, contacts, observed dof, solver and sweep are the scene's. Reading them back
/// gives the same matrices and load bit for bit, hence the same answers.
pub fn export_files(scene: &crate::scene::Scene, structure: &Structure) -> Vec<(String, String)> {
    use std::fmt::Write;
    let model = &structure.model;
    let mut files = vec![
        ("M.mtx".to_string(), matrix_market_text(&model.mass)),
        ("K.mtx".to_string(), matrix_market_text(&model.stiffness)),
    ];
    if let Some(d) = &model.damping {
        files.push(("D.mtx".to_string(), matrix_market_text(d)));
    }
    let (load_files, load_keys) = load_files(&model.load);
    files.extend(load_files);
    let mut t = String::new();
    let title = scene.title.as_deref().unwrap_or("untitled");
    // A TOML string (TOML's escapes, not Rust's `{:?}` ones, which TOML cannot read).
    let title = toml::Value::String(format!("{title} (exported)"));
    let _ = writeln!(t, "title = {title}");
    let _ = writeln!(t, "\n[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"");
    if model.damping.is_some() {
        let _ = writeln!(t, "damping = \"D.mtx\"");
    }
    let _ = writeln!(t, "\n[forcing]\nvector = \"f.mtx\"\namplitude = 1.0");
    let _ = match scene.frequency() {
        FrequencySpec::Ratio(r) => writeln!(t, "omega_ratio = {r:?}"),
        FrequencySpec::Absolute(w) => writeln!(t, "omega = {w:?}"),
    };
    t.push_str(&load_keys);
    t.push_str(&contact_sections(model));
    let _ = writeln!(t, "\n[output]\ndof = {}", structure.observed_dof + 1);
    t.push_str(&solver_section(&scene.solver));
    if let Some(sw) = &scene.sweep {
        let _ = writeln!(
            t,
            "\n[sweep]\nomega_ratio_from = {:?}\nomega_ratio_to = {:?}\nstep = {:?}\nmin_step = {:?}\nmax_step = {:?}\nmax_points = {}",
            sw.omega_ratio_from, sw.omega_ratio_to, sw.step, sw.min_step, sw.max_step, sw.max_points
        );
    }
    files.push((EXPORTED_SCENE.to_string(), t));
    files
}

/// The files of `load` beyond `f.mtx` (its cosine part on harmonic 1), with the `[forcing]`
/// keys that name them: `vector_sin` (`f_sin.mtx`), `static` (`f_static.mtx`) and a
/// `[[forcing.harmonic]]` per higher harmonic (`f_cos_K.mtx`, `f_sin_K.mtx`); parts that are
/// zero are not written. The keys come last in the `[forcing]` section.
fn load_files(load: &HarmonicLoad) -> (Vec<(String, String)>, String) {
    use std::fmt::Write;
    let mut files = vec![(
        "f.mtx".to_string(),
        vector_market_text(&load.forcing_cosine()),
    )];
    let (mut keys, mut tables) = (String::new(), String::new());
    let nonzero = |v: &[f64]| v.iter().any(|x| *x != 0.0);
    for h in load.harmonics() {
        let mut file = |name: String, v: &[f64]| {
            files.push((name.clone(), vector_market_text(v)));
            name
        };
        match h.harmonic {
            0 if nonzero(&h.cosine) => {
                let _ = writeln!(
                    keys,
                    "static = \"{}\"",
                    file("f_static.mtx".into(), &h.cosine)
                );
            }
            1 if nonzero(&h.sine) => {
                let _ = writeln!(
                    keys,
                    "vector_sin = \"{}\"",
                    file("f_sin.mtx".into(), &h.sine)
                );
            }
            k if k >= 2 && (nonzero(&h.cosine) || nonzero(&h.sine)) => {
                let cos = file(format!("f_cos_{k}.mtx"), &h.cosine);
                let sin = file(format!("f_sin_{k}.mtx"), &h.sine);
                let _ = writeln!(
                    tables,
                    "\n[[forcing.harmonic]]\norder = {k}\ncos = \"{cos}\"\nsin = \"{sin}\""
                );
            }
            _ => {}
        }
    }
    (files, keys + &tables)
}

/// The `[[contact.point]]` (with their friction) and `[[friction.point]]` sections of
/// `model`.
fn contact_sections(model: &StructuralModel) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    for (i, c) in model.contacts.iter().enumerate() {
        let _ = writeln!(
            t,
            "\n[[contact.point]]\n{}gap = {:?}",
            row_keys(&c.row, true),
            c.gap
        );
        let on_contact = model
            .friction
            .iter()
            .find(|f| f.normal == NormalForce::Contact(i));
        if let Some(f) = on_contact {
            let (dofs, coefficients) = row_lists(&f.tangent);
            let _ = writeln!(
                t,
                "friction = {:?}\ntangent_dofs = {dofs}\ntangent_coefficients = {coefficients}",
                f.coefficient
            );
        }
    }
    for f in &model.friction {
        if let NormalForce::Prescribed(load) = f.normal {
            let _ = writeln!(
                t,
                "\n[[friction.point]]\n{}normal_load = {load:?}\nfriction = {:?}",
                row_keys(&f.tangent, false),
                f.coefficient
            );
        }
    }
    t
}

/// The `[solver]` section of the settings `v` (the keys that differ from the defaults where
/// a default is implicit).
fn solver_section(v: &SolverSettings) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    let _ = writeln!(t, "\n[solver]\nmethod = \"{}\"", v.method.name());
    let _ = writeln!(
        t,
        "harmonics = {}\ntime_samples = {}",
        v.harmonics, v.time_samples
    );
    if let Some(c) = v.c {
        let _ = writeln!(t, "c = {c:?}");
    }
    if let Some(k) = v.penalty_stiffness {
        let _ = writeln!(t, "penalty_stiffness = {k:?}");
    }
    if v.friction_regularisation != SolverSettings::default().friction_regularisation {
        let _ = writeln!(
            t,
            "friction_regularisation = {:?}",
            v.friction_regularisation
        );
    }
    let lower = |d: String| d.to_lowercase();
    let _ = writeln!(
        t,
        "linear_solver = \"{}\"\nmax_iterations = {}\nglobalization = \"{}\"\ntolerance = {:?}",
        v.linear_solver.name(),
        v.max_iterations,
        lower(format!("{:?}", v.globalization)),
        v.tolerance
    );
    let _ = writeln!(
        t,
        "steps_per_period = {}\nmax_periods = {}\nmarch_tolerance = {:?}\nrestitution = {:?}\nlcp_scheme = \"{}\"",
        v.steps_per_period,
        v.max_periods,
        v.march_tolerance,
        v.restitution,
        v.lcp_scheme.name()
    );
    t
}

/// The scene keys of a row, one per line: `dof` (with `direction` when `with_direction`:
/// contacts take one, friction points none) for one dof with coefficient `+1` (or `-1`
/// with a direction), else `dofs` and `coefficients`.
fn row_keys(row: &ContactRow, with_direction: bool) -> String {
    match row.single() {
        Some((dof, a)) if with_direction && a.abs() == 1.0 => {
            format!("dof = {}\ndirection = {}\n", dof + 1, a as i32)
        }
        Some((dof, 1.0)) => format!("dof = {}\n", dof + 1),
        _ => {
            let (dofs, coefficients) = row_lists(row);
            format!("dofs = {dofs}\ncoefficients = {coefficients}\n")
        }
    }
}

/// A row's 1-based dofs and its coefficients as TOML arrays.
fn row_lists(row: &ContactRow) -> (String, String) {
    let dofs: Vec<String> = row.dofs().iter().map(|d| (d + 1).to_string()).collect();
    let coefficients: Vec<String> = row
        .coefficients()
        .iter()
        .map(|a| format!("{a:?}"))
        .collect();
    (
        format!("[{}]", dofs.join(", ")),
        format!("[{}]", coefficients.join(", ")),
    )
}
