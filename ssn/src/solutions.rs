//! `ssn solutions SCENE`: every periodic response at the scene's frequency with its
//! stability ([`semismooth_contact::solutions::find_solutions`]).

#[cfg(feature = "cli")]
use semismooth_contact::{
    model::Structure,
    solutions::{find_solutions, PeriodicSolution, SolutionSet},
    solve::RunError,
};

#[cfg(feature = "cli")]
use crate::output::{csv_table, line_plot_svg, LineStyle, PlotSpec, Series};

/// `ssn solutions SCENE`: every periodic solution at the scene's frequency (module
/// documentation); text or JSON on stdout, a CSV row per solution, an SVG of the tip over
/// one period (stable solid, unstable dashed, undecided dotted).
#[cfg(feature = "cli")]
pub fn command(args: &crate::cli::RunArgs) -> Result<(), crate::exit::CliError> {
    use crate::exit::CliError;
    let crate::cli::Loaded {
        scene,
        structure: rod,
        omega,
    } = crate::cli::load_with(&args.scene, &args.set, crate::cli::Workload::Branch)?;
    let mut outputs = args.plan()?;
    crate::cli::claim_model_files(&mut outputs, &scene)?;
    check_window(&scene, omega / rod.omega_1)?;
    let bad = |e: RunError| CliError::BadInput(format!("{}: {e}", args.scene.display()));
    let set = find_solutions(&rod, omega, &scene.solver, scene.sweep.as_ref()).map_err(bad)?;
    if let Some(csv) = &args.csv {
        outputs.add(csv, csv_text(&set).into_bytes());
    }
    if let Some(svg) = &args.svg {
        outputs.add(svg, svg_text(&set, &rod)?.into_bytes());
    }
    let complete = incomplete(&set).is_none();
    args.finish(outputs, || document(&set), || summary(&set), complete)
}

/// The CSV of `ssn solutions`: a row per solution.
#[cfg(feature = "cli")]
fn csv_text(set: &SolutionSet) -> String {
    let column = |f: &dyn Fn(&PeriodicSolution) -> f64| -> Vec<f64> {
        set.solutions.iter().map(f).collect()
    };
    let columns = [
        column(&|s| s.solution.stats.min),
        column(&|s| s.solution.stats.max),
        column(&|s| s.solution.stats.mean_contact_force),
        column(&|s| s.solution.stats.max_penetration),
        column(&|s| {
            s.stability
                .stable
                .map_or(f64::NAN, |b| f64::from(u8::from(b)))
        }),
        column(&|s| s.stability.floquet_max_abs.unwrap_or(f64::NAN)),
    ];
    let refs: Vec<&[f64]> = columns.iter().map(|c| c.as_slice()).collect();
    let headers = [
        "tip_min",
        "tip_max",
        "contact_force_mean",
        "max_penetration",
        "stable",
        "floquet_max_abs",
    ];
    csv_table(&headers, &refs)
}

/// The SVG of `ssn solutions`: the tip of each solution over one period, styled by its
/// stability, with the obstacles of `rod`.
#[cfg(feature = "cli")]
fn svg_text(set: &SolutionSet, rod: &Structure) -> Result<String, crate::exit::CliError> {
    let mut series: Vec<Series> = set
        .solutions
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let t: Vec<f64> = s
                .solution
                .times
                .iter()
                .map(|t| t * set.omega / (2.0 * std::f64::consts::PI))
                .collect();
            let label = match s.stability.stable {
                Some(true) => format!("solution {} (stable)", k + 1),
                Some(false) => format!("solution {} (unstable)", k + 1),
                None => format!("solution {} (stability undecided)", k + 1),
            };
            // The stability styles of the sweeps: solid, dashed, dotted.
            let style = match s.stability.stable {
                Some(true) => LineStyle::Solid,
                Some(false) => LineStyle::Dashed,
                None => LineStyle::Dotted,
            };
            Series {
                style,
                ..Series::new(label, t, s.solution.observed.clone())
            }
        })
        .collect();
    series.extend(crate::figures::obstacle_lines(rod, 0.0, 1.0));
    let spec = PlotSpec {
        title: format!(
            "periodic solutions at omega/omega_1 = {:.4}",
            set.omega / set.omega_1
        ),
        x_label: "time t / T (T: forcing period)".into(),
        y_label: "tip displacement u_tip".into(),
        log_log: false,
    };
    Ok(line_plot_svg(&spec, &series)?)
}

/// The text summary of `ssn solutions`: the search, each solution with its stability,
/// what was not corrected or missed, and the work.
#[cfg(feature = "cli")]
fn summary(set: &SolutionSet) -> String {
    let mut t = format!(
        "omega/omega_1     {:.6}: {} solution(s) from {} crossing(s) of a {}-point branch \
         over [{}, {}]\n",
        set.omega / set.omega_1,
        set.solutions.len(),
        set.crossings,
        set.branch_points,
        set.window.0,
        set.window.1
    );
    for (k, s) in set.solutions.iter().enumerate() {
        t += &format!(
            "  {}: tip min {:.6} max {:.6}, mean contact force {:.4e}, {} (max |mu| {})\n",
            k + 1,
            s.solution.stats.min,
            s.solution.stats.max,
            s.solution.stats.mean_contact_force,
            match s.stability.stable {
                Some(true) => "stable".to_string(),
                Some(false) => "unstable".to_string(),
                None => format!(
                    "undecided: {}",
                    s.stability
                        .undecided
                        .as_ref()
                        .map(crate::words::undecided)
                        .unwrap_or_default()
                ),
            },
            s.stability
                .floquet_max_abs
                .map_or("-".to_string(), |m| format!("{m:.4}"))
        );
    }
    for f in &set.failed_corrections {
        t += &format!("  not corrected: {}\n", crate::words::failed_correction(f));
    }
    if let Some(missed) = incomplete(set) {
        t += &format!("  incomplete search: {missed}\n");
    }
    if set.counters.krylov_iterations > 0 {
        t += &format!(
            "  work: {} GMRES iterations (matrix-free condensed solves)\n",
            set.counters.krylov_iterations
        );
    }
    if !set.solutions.is_empty() {
        t += "  (--json carries each solution's state: ssn solve SCENE --start FILE --entry K \
              starts from solution K)\n";
    }
    t
}

/// The JSON document of `ssn solutions --json`: [`crate::json::solutions_json`] with
/// `converged` (the search finished: `incomplete` is `None`, exit code 0) and
/// `incomplete` (what it missed, in words, or null).
pub fn document(set: &semismooth_contact::solutions::SolutionSet) -> serde_json::Value {
    let mut v = crate::json::solutions_json(set);
    v["converged"] = incomplete(set).is_none().into();
    v["incomplete"] = incomplete(set).into();
    v
}

/// What a search that did not finish missed, in words; `None` when it finished: its
/// branch crossed the whole window, every crossing was corrected and at least one was
/// found (a branch through the window crosses the scene's frequency).
fn incomplete(set: &semismooth_contact::solutions::SolutionSet) -> Option<String> {
    let mut missed = Vec::new();
    if !set.branch_converged {
        missed.push(format!(
            "the branch stopped after {} points before the end of the window [{}, {}]: \
             solutions on the rest of it are missing",
            set.branch_points, set.window.0, set.window.1
        ));
    }
    if !set.failed_corrections.is_empty() {
        missed.push(format!(
            "{} crossing(s) could not be corrected",
            set.failed_corrections.len()
        ));
    }
    if set.branch_converged && set.solutions.is_empty() {
        missed.push(
            "no solution found, yet a branch through the window crosses the frequency".into(),
        );
    }
    (!missed.is_empty()).then(|| missed.join("; "))
}

/// Refuses a forcing frequency outside the `[sweep]` window searched (exit code 2), naming
/// the scene's own frequency key.
#[cfg(feature = "cli")]
fn check_window(scene: &crate::scene::Scene, ratio: f64) -> Result<(), crate::exit::CliError> {
    use semismooth_contact::rod::FrequencySpec;
    let Some(sweep) = &scene.sweep else {
        return Ok(());
    };
    let (lo, hi) = (
        sweep.omega_ratio_from.min(sweep.omega_ratio_to),
        sweep.omega_ratio_from.max(sweep.omega_ratio_to),
    );
    if lo <= ratio && ratio <= hi {
        return Ok(());
    }
    let (key, value) = match scene.frequency() {
        FrequencySpec::Ratio(r) => ("forcing.omega_ratio", r),
        FrequencySpec::Absolute(w) => ("forcing.omega", w),
    };
    Err(crate::exit::CliError::BadInput(format!(
        "{}: invalid `{key}` = {value} (omega / omega_1 = {ratio}): allowed a frequency inside \
         the [sweep] window omega_ratio_from..omega_ratio_to = [{lo}, {hi}] that ssn solutions \
         searches",
        crate::io::printable(&scene.path.display().to_string())
    )))
}
