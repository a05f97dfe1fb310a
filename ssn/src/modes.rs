//! `ssn modes SCENE`: the backbone of a nonlinear mode ([`semismooth_contact::modes`],
//! EPMC on SSN-HB) over the scene's `[modes]` amplitude range of the observed dof, or its
//! energy range. Another `solver.method` is refused: EPMC is posed on SSN-HB alone.

use serde_json::{json, Value};

use semismooth::continuation::ContinuationTermination;
use semismooth_contact::hb::HbOptions;
use semismooth_contact::model::Structure;
use semismooth_contact::modes::{
    backbone, AmplitudeMeasure, Backbone, BackboneOptions, EpmcSolve, MAX_DENSE_UNKNOWNS,
};

#[cfg(feature = "cli")]
use crate::cli::{Loaded, RunArgs, Workload};
#[cfg(feature = "cli")]
use crate::exit::CliError;
#[cfg(feature = "cli")]
use crate::output::{csv_table, line_plot_svg, LineStyle, PlotSpec, Series};
use crate::scene::{Method, Scene};

/// `ssn modes SCENE`: the backbone (module documentation); text or JSON on stdout, a CSV
/// row per point, an SVG of the frequency and the damping ratio against the amplitude.
#[cfg(feature = "cli")]
pub fn command(args: &RunArgs) -> Result<(), CliError> {
    let mut outputs = args.plan()?;
    let Loaded {
        scene, structure, ..
    } = crate::cli::load_with(&args.scene, &args.set, Workload::Branch)?;
    crate::cli::claim_model_files(&mut outputs, &scene)?;
    let bad = |e: String| CliError::BadInput(format!("{}: {e}", args.scene.display()));
    let started = std::time::Instant::now();
    let branch = run(&scene, &structure).map_err(bad)?;
    let seconds = started.elapsed().as_secs_f64();
    if let Some(csv) = &args.csv {
        outputs.add(csv, csv_text(&branch).into_bytes());
    }
    if let Some(svg) = &args.svg {
        outputs.add(svg, svg_text(&scene, &branch)?.into_bytes());
    }
    let complete = matches!(
        branch.termination,
        ContinuationTermination::ReachedBound { .. }
    );
    args.finish(
        outputs,
        || document(&scene, &branch, structure.omega_1, seconds),
        || summary(&branch),
        complete,
    )
}

/// The backbone of `scene`'s `[modes]` on `structure` (the observed dof's amplitude, the
/// scene's harmonic balance); `Err` names what is missing or wrong.
pub fn run(scene: &Scene, structure: &Structure) -> Result<Backbone, String> {
    let Some(settings) = scene.modes.clone() else {
        return Err(
            "no [modes] section: add amplitude_from and amplitude_to (the observed \
                    dof's amplitude)"
                .into(),
        );
    };
    if scene.solver.method != Method::SsnHb {
        return Err(format!(
            "solver.method = \"{}\": ssn modes computes the extended periodic motion on \
             ssn-hb only (set solver.method = \"ssn-hb\" or leave it out)",
            scene.solver.method.name()
        ));
    }
    let measure = AmplitudeMeasure::Dof(structure.observed_dof);
    let mut options = match settings.energy_range {
        Some((from, to)) => BackboneOptions::by_energy(settings.mode, measure, from, to),
        None => BackboneOptions::new(
            settings.mode,
            measure,
            settings.amplitude_from,
            settings.amplitude_to,
        ),
    };
    options.hb = HbOptions {
        harmonics: scene.solver.harmonics,
        time_samples: Some(scene.solver.time_samples),
        c: scene.solver.c,
    };
    options.continuation.max_points = settings.max_points;
    // Beyond the dense bordered solve's reach, the structured one (same equations).
    let model = &structure.model;
    let rows = model.dofs() + model.contact_count() + model.friction_count();
    if rows.saturating_mul(2 * scene.solver.harmonics + 1) + 2 > MAX_DENSE_UNKNOWNS {
        options.solve = EpmcSolve::Structured;
    }
    backbone(model, &options).map_err(|e| e.to_string())
}

/// The JSON document of `ssn modes` (also `ssn.modes(scene)` in Python).
pub fn document(scene: &Scene, branch: &Backbone, omega_1: f64, seconds: f64) -> Value {
    let points: Vec<Value> = branch
        .points
        .iter()
        .map(|p| {
            json!({
                "amplitude": p.amplitude,
                "energy": p.energy,
                "omega": p.omega,
                "omega_ratio": p.omega / omega_1,
                "damping_ratio": p.damping_ratio,
                "modal_damping": p.modal_damping,
                "displacement_max": p.summary.displacement_max,
                "displacement_min": p.summary.displacement_min,
                "max_penetration": p.summary.max_penetration,
                "contacts": p.summary.contact_force_mean.iter()
                    .map(|f| json!({ "force_mean": f })).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({
        "scene": scene.path.display().to_string(),
        "mode": branch.linear.index,
        "linear": { "omega": branch.linear.omega, "damping_ratio": branch.linear.damping_ratio },
        "observed_dof": branch.summary_dof,
        "harmonics": scene.solver.harmonics,
        "damping_convention": "damping_ratio = modal_damping / (2 omega) (NLvib); the motion \
            solves M u'' + (D - modal_damping M) u' + K u = G^T lambda",
        "amplitude_measure": "cosine part of harmonic 1 of the observed dof, sine part zero",
        "points": points,
        "folds": branch.folds,
        "converged": matches!(branch.termination, ContinuationTermination::ReachedBound { .. }),
        "termination": format!("{:?}", branch.termination),
        "solve_seconds": seconds,
        "bordered_solve": format!("{:?}", branch.solve).to_lowercase(),
    })
}

/// One CSV row per point.
#[cfg(feature = "cli")]
fn csv_text(branch: &Backbone) -> String {
    let column = |f: &dyn Fn(&semismooth_contact::modes::BackbonePoint) -> f64| -> Vec<f64> {
        branch.points.iter().map(f).collect()
    };
    let columns = [
        column(&|p| p.amplitude),
        column(&|p| p.energy),
        column(&|p| p.omega),
        column(&|p| p.damping_ratio),
        column(&|p| p.modal_damping),
        column(&|p| p.summary.max_penetration),
    ];
    let refs: Vec<&[f64]> = columns.iter().map(|c| c.as_slice()).collect();
    let headers = [
        "amplitude",
        "energy",
        "omega",
        "damping_ratio",
        "modal_damping",
        "max_penetration",
    ];
    csv_table(&headers, &refs)
}

/// The frequency against the amplitude, and the damping ratio (times `omega_n`, to share
/// the axis) when the mode is damped.
#[cfg(feature = "cli")]
fn svg_text(scene: &Scene, branch: &Backbone) -> Result<String, CliError> {
    let amplitude: Vec<f64> = branch.points.iter().map(|p| p.amplitude).collect();
    let mut series = vec![Series {
        label: "omega".into(),
        x: amplitude.clone(),
        y: branch.points.iter().map(|p| p.omega).collect(),
        style: LineStyle::Solid,
        color: None,
    }];
    if branch.points.iter().any(|p| p.damping_ratio != 0.0) {
        series.push(Series {
            label: "damping ratio x omega_n".into(),
            x: amplitude,
            y: (branch.points.iter())
                .map(|p| p.damping_ratio * branch.linear.omega)
                .collect(),
            style: LineStyle::Dashed,
            color: None,
        });
    }
    let spec = PlotSpec {
        title: scene
            .title
            .clone()
            .unwrap_or_else(|| "nonlinear mode".into()),
        x_label: "amplitude of the observed dof".into(),
        y_label: "omega".into(),
        log_log: false,
    };
    Ok(line_plot_svg(&spec, &series)?)
}

/// The text summary: the linear mode, the range covered, the extremes of the frequency
/// and of the damping ratio, why it ended.
#[cfg(feature = "cli")]
fn summary(branch: &Backbone) -> String {
    let fold = |init: f64,
                f: fn(f64, f64) -> f64,
                g: &dyn Fn(&semismooth_contact::modes::BackbonePoint) -> f64| {
        branch.points.iter().map(g).fold(init, f)
    };
    format!(
        "mode {}: linear omega {:.6}, damping ratio {:.3e}\n\
         {} points, amplitude {:.4e} .. {:.4e}\n\
         omega {:.6} .. {:.6}, damping ratio {:.3e} .. {:.3e}\n\
         {} folds; ended: {:?}\n",
        branch.linear.index,
        branch.linear.omega,
        branch.linear.damping_ratio,
        branch.points.len(),
        fold(f64::INFINITY, f64::min, &|p| p.amplitude),
        fold(f64::NEG_INFINITY, f64::max, &|p| p.amplitude),
        fold(f64::INFINITY, f64::min, &|p| p.omega),
        fold(f64::NEG_INFINITY, f64::max, &|p| p.omega),
        fold(f64::INFINITY, f64::min, &|p| p.damping_ratio),
        fold(f64::NEG_INFINITY, f64::max, &|p| p.damping_ratio),
        branch.folds.len(),
        branch.termination,
    )
}
