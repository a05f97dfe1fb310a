//! The `ssn` command-line program's commands, as library functions (so tests and examples
//! can call them): `solve`, `scene-check` and the default run that reproduces the paper.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use serde_json::{json, Value};

use crate::output::{
    csv_table, prepare_directory, write_atomically, write_line_plot, PlotSpec, Series,
};
use crate::rod::{build_rod, MassModel, RodModel, RodSpec};
use crate::runner::{solve_rod, RunCounters, RunError, Solution};
use crate::scene::{default_hb_time_samples, Method, Scene, SolverSettings};

/// How a command failed, mapped by `main` onto the documented exit codes.
#[derive(Debug)]
pub enum CliError {
    /// The solver ran but did not converge (exit code 1); its output was printed.
    NotConverged,
    /// Bad input: scene, option (exit code 2).
    BadInput(String),
    /// An output could not be written (exit code 3).
    Output(String),
}

impl From<crate::output::OutputError> for CliError {
    fn from(e: crate::output::OutputError) -> Self {
        CliError::Output(e.to_string())
    }
}

fn run_error(path: &Path, e: RunError) -> CliError {
    CliError::BadInput(format!("{}: {e}", path.display()))
}

/// Loads a scene and builds its rod.
pub fn load(path: &Path) -> Result<(Scene, RodModel), CliError> {
    let scene = Scene::from_path(path).map_err(|e| CliError::BadInput(e.to_string()))?;
    let rod = build_rod(&scene.rod)
        .map_err(|e| CliError::BadInput(format!("{}: {e}", path.display())))?;
    Ok((scene, rod))
}

/// Largest number of folds listed one by one in the human-readable sweep summary.
const LISTED_FOLDS: usize = 8;

/// The folds of a sweep in words (units of omega_1): all of them when there are few; else
/// their count, range, first and last (LCP and stiff-penalty branches have tens to
/// hundreds of small folds where the contact moves from node to node; `--json` and
/// `--csv` keep every one).
fn folds_summary(folds: &[f64], omega_1: f64) -> String {
    let ratio: Vec<f64> = folds.iter().map(|w| w / omega_1).collect();
    match ratio.len() {
        0 => "none".into(),
        n if n <= LISTED_FOLDS => ratio
            .iter()
            .map(|r| format!("{r:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
        n => {
            let lo = ratio.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = ratio.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            format!(
                "{n} between {lo:.4} and {hi:.4} (first {:.4}, last {:.4}; all in --json)",
                ratio[0],
                ratio[n - 1]
            )
        }
    }
}

/// The JSON object of the work counters.
pub fn counters_json(c: &RunCounters) -> Value {
    json!({
        "residual_evaluations": c.residual_evaluations,
        "jacobian_evaluations": c.jacobian_evaluations,
        "factorizations": c.factorizations,
        "linear_solves": c.linear_solves,
        "line_search_backtracks": c.line_search_backtracks,
        "ffts": c.ffts,
        "lemke_pivots": c.lemke_pivots,
        "time_steps": c.time_steps,
    })
}

/// The JSON document of `ssn solve --json` (documented in README.md). `harmonics` is absent
/// for the LCP and time marching; `time_samples` is then the number of steps per period.
pub fn solution_json(scene: &Path, s: &Solution) -> Value {
    let mut v = json!({
        "scene": scene.display().to_string(),
        "method": s.method.name(),
        "time_samples": s.time_samples,
        "omega": s.omega,
        "omega_ratio": s.omega / s.omega_1,
        "converged": s.converged,
        "termination": s.termination,
        "iterations": s.iterations,
        "residual_norm": finite_or_null(s.residual_norm),
        "solve_seconds": s.solve_seconds,
        "tip_max": finite_or_null(s.stats.max),
        "tip_min": finite_or_null(s.stats.min),
        "max_penetration": finite_or_null(s.stats.max_penetration),
        "contact_force_mean": finite_or_null(s.stats.mean_contact_force),
        "counters": counters_json(&s.counters),
    });
    if let Some(h) = s.harmonics {
        v["harmonics"] = json!(h);
    }
    if let Some(c) = s.c {
        v["c"] = json!(c);
    }
    v
}

fn finite_or_null(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// `ssn solve SCENE`: one periodic response; text or JSON on stdout, optional CSV/SVG.
pub fn solve(
    path: &Path,
    as_json: bool,
    csv: Option<&Path>,
    svg: Option<&Path>,
    quiet: bool,
) -> Result<(), CliError> {
    let (scene, rod) = load(path)?;
    // Time marching to a steady state is the long one: a spinner while it runs.
    let bar = if scene.solver.method == Method::March {
        progress_spinner("time marching to a steady state", quiet)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let solution = solve_rod(&rod, &scene.solver, None).map_err(|e| run_error(path, e))?;
    bar.finish_and_clear();
    if let Some(csv) = csv {
        let mut columns: Vec<&[f64]> = vec![&solution.times, &solution.tip];
        let mut headers = vec!["t".to_string(), "u_tip".to_string()];
        for (i, f) in solution.contact_forces.iter().enumerate() {
            columns.push(f);
            headers.push(format!("lambda_{i}"));
        }
        let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
        write_atomically(csv, csv_table(&headers, &columns).as_bytes())?;
    }
    if let Some(svg) = svg {
        let period = 2.0 * std::f64::consts::PI / solution.omega;
        let phase: Vec<f64> = solution.times.iter().map(|t| t / period).collect();
        write_line_plot(
            svg,
            &PlotSpec {
                title: scene
                    .title
                    .clone()
                    .unwrap_or_else(|| "tip displacement".into()),
                x_label: "t / T".into(),
                y_label: "u_tip".into(),
                log_log: false,
            },
            &[Series::new(
                describe_method(&solution),
                phase,
                solution.tip.clone(),
            )],
        )?;
    }
    if as_json {
        println!(
            "{}",
            serde_json::to_string_pretty(&solution_json(path, &solution))
                .expect("JSON of plain values")
        );
    } else {
        print_solution(&solution);
    }
    if solution.converged {
        Ok(())
    } else {
        Err(CliError::NotConverged)
    }
}

fn describe_method(s: &Solution) -> String {
    match s.harmonics {
        Some(h) => format!("{} H={h} Nt={}", s.method.name(), s.time_samples),
        None => format!("{} Nt={}", s.method.name(), s.time_samples),
    }
}

fn print_solution(s: &Solution) {
    println!("method            {}", describe_method(s));
    println!(
        "omega             {:.6} ({:.4} omega_1)",
        s.omega,
        s.omega / s.omega_1
    );
    println!(
        "converged         {} ({}), {} iterations, residual {:.3e}",
        s.converged, s.termination, s.iterations, s.residual_norm
    );
    println!("solve time        {:.3} ms", 1e3 * s.solve_seconds);
    println!("tip max / min     {:.6} / {:.6}", s.stats.max, s.stats.min);
    println!("max penetration   {:.3e}", s.stats.max_penetration);
    println!("mean contact force {:.6e}", s.stats.mean_contact_force);
    let c = &s.counters;
    println!(
        "work              {} residuals, {} Jacobians, {} factorizations, {} solves, {} FFTs",
        c.residual_evaluations, c.jacobian_evaluations, c.factorizations, c.linear_solves, c.ffts
    );
}

/// `ssn sweep SCENE`: the frequency response over the scene's `[sweep]` range by
/// pseudo-arclength continuation; text or JSON on stdout, optional CSV/SVG.
pub fn sweep(
    path: &Path,
    as_json: bool,
    csv: Option<&Path>,
    svg: Option<&Path>,
    quiet: bool,
) -> Result<(), CliError> {
    let (scene, rod) = load(path)?;
    let Some(settings) = scene.sweep.as_ref() else {
        return Err(CliError::BadInput(format!(
            "{}: no [sweep] section: add omega_ratio_from and omega_ratio_to (units of omega_1)",
            path.display()
        )));
    };
    let bar = progress_spinner("sweep", quiet);
    let progress = |points: usize, omega: f64| {
        bar.set_message(format!(
            "sweep: {points} points, omega/omega_1 = {:.4}",
            omega / rod.omega_1
        ));
        bar.tick();
    };
    let response = crate::sweep::frequency_response(&rod, &scene.solver, settings, Some(&progress))
        .map_err(|e| run_error(path, e))?;
    bar.finish_and_clear();
    let ratio = response.omega_ratio();
    if let Some(csv) = csv {
        let text = csv_table(
            &["omega", "omega_ratio", "tip_max", "tip_min", "amplitude"],
            &[
                &response.omega,
                &ratio,
                &response.tip_max,
                &response.tip_min,
                &response.amplitude,
            ],
        );
        write_atomically(csv, text.as_bytes())?;
    }
    if let Some(svg) = svg {
        write_line_plot(
            svg,
            &PlotSpec {
                title: scene
                    .title
                    .clone()
                    .unwrap_or_else(|| "frequency response".into()),
                x_label: "omega / omega_1".into(),
                y_label: "max |u_tip|".into(),
                log_log: false,
            },
            &[Series::new(
                format!(
                    "{} H = {}",
                    scene.solver.method.name(),
                    scene.solver.harmonics
                ),
                ratio.clone(),
                response.amplitude.clone(),
            )],
        )?;
    }
    if as_json {
        println!(
            "{}",
            serde_json::to_string_pretty(&response.to_json()).expect("JSON of plain values")
        );
    } else {
        println!(
            "sweep             {} points, omega/omega_1 from {:.4} to {:.4}",
            response.points(),
            ratio.first().copied().unwrap_or(f64::NAN),
            ratio.last().copied().unwrap_or(f64::NAN)
        );
        if let Some((i, a)) = response.peak() {
            println!(
                "peak amplitude    {a:.6} at omega/omega_1 = {:.4}",
                ratio[i]
            );
        }
        println!(
            "folds             {}",
            folds_summary(&response.folds, rod.omega_1)
        );
        println!(
            "converged         {} ({}), {:.3} s",
            response.converged, response.termination, response.solve_seconds
        );
    }
    if response.converged {
        Ok(())
    } else {
        Err(CliError::NotConverged)
    }
}

/// `ssn compare SCENE`: accuracy against cost of every applicable method on the scene's rod
/// (error of the tip minimum against a converged reference versus wall time); prints the
/// table and the cheapest setting of each method for `accuracy`, writes
/// `accuracy_cost.csv` and `accuracy_cost.svg` into `out`.
pub fn compare(path: &Path, out: &Path, accuracy: f64, quiet: bool) -> Result<(), CliError> {
    if !(accuracy.is_finite() && accuracy > 0.0) {
        return Err(CliError::BadInput(format!(
            "invalid --accuracy {accuracy}: allowed a finite number > 0 (relative error of the tip minimum)"
        )));
    }
    let (scene, rod) = load(path)?;
    prepare_directory(out)?;
    let bar = progress_spinner("compare", quiet);
    let say = |line: &str| {
        bar.set_message(line.to_string());
        bar.tick();
    };
    let study = crate::study::accuracy_cost(&rod, &scene.solver, Some(&say))
        .map_err(|e| run_error(path, e))?;
    bar.finish_and_clear();
    print!("{}", study.table());
    println!("\nCheapest setting of each method for a relative accuracy of {accuracy:e} on the tip minimum:");
    for (method, entry) in study.cheapest(accuracy) {
        match entry {
            Some(e) => println!(
                "  {:<11} {:<28} {:>10.3} ms  (error {:.1e})",
                method.name(),
                e.setting,
                1e3 * e.seconds,
                e.tip_min_error
            ),
            None => println!(
                "  {:<11} none of the settings tried reaches it",
                method.name()
            ),
        }
    }
    write_atomically(&out.join("accuracy_cost.csv"), study.to_csv().as_bytes())?;
    study.write_svg(&out.join("accuracy_cost.svg"))?;
    println!(
        "\nWrote {}/accuracy_cost.csv and accuracy_cost.svg",
        out.display()
    );
    Ok(())
}

/// A spinner on stderr when it is a terminal and not `quiet`.
pub fn progress_spinner(message: &str, quiet: bool) -> indicatif::ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_message(message.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}

/// The resolved model of a scene, in words (`ssn scene-check`).
pub fn describe(scene: &Scene, rod: &RodModel, modes: &[f64]) -> String {
    use crate::rod::{DampingSpec, FrequencySpec, LoadKind};
    let s = &rod.spec;
    let mut out = String::new();
    let mut line = |t: String| {
        out.push_str(&t);
        out.push('\n');
    };
    line(format!("scene             {}", scene.path.display()));
    if let Some(t) = &scene.title {
        line(format!("title             {t}"));
    }
    line(format!(
        "rod               {} elements, L = {}, EA = {}, rhoA = {}, {:?} mass",
        s.elements, s.length, s.axial_stiffness, s.mass_per_length, s.mass
    ));
    line(format!(
        "unknowns          {} dofs (node 0 clamped)",
        rod.model.dofs()
    ));
    let freqs: Vec<String> = modes.iter().map(|w| format!("{w:.6}")).collect();
    line(format!("natural freqs     {}", freqs.join(", ")));
    line(match s.damping {
        None => "damping           none (no damping matrix)".into(),
        Some(DampingSpec::StiffnessProportional { zeta }) => format!(
            "damping           D = beta K, beta = 2 zeta / omega_1 = {:.6e} (zeta = {zeta})",
            2.0 * zeta / rod.omega_1
        ),
        Some(DampingSpec::Rayleigh { alpha, beta }) => {
            format!("damping           D = {alpha} M + {beta} K")
        }
    });
    let ratio = match s.frequency {
        FrequencySpec::Ratio(r) => r,
        FrequencySpec::Absolute(w) => w / rod.omega_1,
    };
    line(format!(
        "forcing           {} p0 = {}, omega = {:.6} ({:.4} omega_1)",
        match s.load {
            LoadKind::Distributed => "distributed",
            LoadKind::Tip => "tip force",
        },
        s.amplitude,
        rod.model.forcing.omega,
        ratio
    ));
    if s.contacts.is_empty() {
        line("contact           none: linear problem (one factorization, no FFT)".into());
    } else {
        for c in &s.contacts {
            line(format!(
                "contact           node {} (dof {}), gap {}{}",
                c.node,
                c.node - 1,
                c.gap,
                if c.node == s.elements { " (tip)" } else { "" }
            ));
        }
        line(format!(
            "contact stiffness static {:.6e} (default c = 10 x static = {:.6e}), local K[dof,dof] = {:.6e} (penalty unit)",
            rod.model.static_contact_stiffness().unwrap_or(f64::NAN),
            rod.model.default_complementarity_constant(),
            rod.model.contact_stiffness_scale()
        ));
    }
    let v = &scene.solver;
    line(match v.method {
        m if m.is_harmonic_balance() => format!(
            "solver            {} H = {}, Nt = {}, {:?} linear solver, {:?} globalization",
            m.name(),
            v.harmonics,
            v.time_samples,
            v.linear_solver,
            v.globalization
        ),
        Method::March => format!(
            "solver            march, {} steps per period, tolerance {:e}",
            v.steps_per_period, v.march_tolerance
        ),
        m => format!(
            "solver            {}, Nt = {} steps per period",
            m.name(),
            v.time_samples
        ),
    });
    if let Some(sw) = &scene.sweep {
        line(format!(
            "sweep             omega/omega_1 from {} to {}, step {} in [{}, {}], at most {} points",
            sw.omega_ratio_from,
            sw.omega_ratio_to,
            sw.step,
            sw.min_step,
            sw.max_step,
            sw.max_points
        ));
    }
    let massive: Vec<String> = rod
        .model
        .contacts
        .iter()
        .filter(|c| crate::model::diagonal_entry(&rod.model.mass, c.dof) > 0.0)
        .map(|c| (c.dof + 1).to_string())
        .collect();
    if !massive.is_empty() {
        line(format!(
            "note              contact node(s) {} carry mass: time marching then needs an impact \
             law and harmonic balance imposes none, so the two need not agree, and the periodic \
             LCP may be hard for Lemke; mass = \"modified\" makes the tip contact massless",
            massive.join(", ")
        ));
    }
    out
}

/// A progress bar on stderr when it is a terminal and not `quiet`.
pub fn progress_bar(len: u64, message: &str, quiet: bool) -> indicatif::ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg:32} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(message.to_string());
    bar
}

/// One row of the default run's Fig. 1 table.
#[derive(Debug, Clone)]
pub struct Fig1Row {
    /// Mass model.
    pub mass: MassModel,
    /// Harmonics (None for the reference).
    pub harmonics: Option<usize>,
    /// Newton iterations (periods for the reference).
    pub iterations: usize,
    /// Wall time of the solve.
    pub seconds: f64,
    /// Tip minimum over the period.
    pub tip_min: f64,
    /// Tip maximum over the period.
    pub tip_max: f64,
    /// Relative difference of the tip minimum to the reference.
    pub difference: f64,
}

/// Writes `<stem>.svg` (the series) and `<stem>.csv` (the named columns) into `out`.
fn write_figure(
    out: &Path,
    stem: &str,
    plot: &PlotSpec,
    series: &[Series],
    columns: &[(String, Vec<f64>)],
) -> Result<(), CliError> {
    write_line_plot(&out.join(format!("{stem}.svg")), plot, series)?;
    let headers: Vec<&str> = columns.iter().map(|(h, _)| h.as_str()).collect();
    let data: Vec<&[f64]> = columns.iter().map(|(_, c)| c.as_slice()).collect();
    write_atomically(
        &out.join(format!("{stem}.csv")),
        csv_table(&headers, &data).as_bytes(),
    )?;
    Ok(())
}

/// Fig. 1 of the paper for one mass model: SSN-HB at H = 10, 15, 20 against the time-marching
/// reference; writes `fig1_<mass>.svg` and `.csv` into `out`.
pub fn figure_1(out: &Path, mass: MassModel, quiet: bool) -> Result<Vec<Fig1Row>, CliError> {
    let spec = RodSpec {
        mass,
        ..RodSpec::canonical()
    };
    let rod = build_rod(&spec).map_err(|e| CliError::BadInput(e.to_string()))?;
    let name = match mass {
        MassModel::Consistent => "consistent",
        MassModel::Lumped => "lumped",
        MassModel::Modified => "modified",
    };
    let bar = progress_bar(4, &format!("Fig. 1 ({name} mass)"), quiet);
    // Reference: energy-conserving trapezoidal steps with a massless contact node; the
    // Moreau–Jean scheme (restitution 0) otherwise, with finer steps (first order).
    let reference_settings = SolverSettings {
        method: Method::March,
        steps_per_period: if mass == MassModel::Modified {
            4000
        } else {
            8000
        },
        march_tolerance: if mass == MassModel::Modified {
            1e-9
        } else {
            1e-6
        },
        ..default_settings(20)
    };
    let reference = solve_rod(&rod, &reference_settings, None)
        .map_err(|e| CliError::BadInput(e.to_string()))?;
    bar.inc(1);
    let period = 2.0 * std::f64::consts::PI / reference.omega;
    let mut series = Vec::new();
    let mut csv_columns: Vec<(String, Vec<f64>)> = Vec::new();
    let mut rows = Vec::new();
    for h in [10usize, 15, 20] {
        let settings = default_settings(h);
        let s = solve_rod(&rod, &settings, None).map_err(|e| CliError::BadInput(e.to_string()))?;
        bar.inc(1);
        let phase: Vec<f64> = s.times.iter().map(|t| t / period).collect();
        series.push(Series::new(
            format!("SSN-HB H = {h}"),
            phase.clone(),
            s.tip.clone(),
        ));
        csv_columns.push((format!("t_over_T_H{h}"), phase));
        csv_columns.push((format!("u_tip_H{h}"), s.tip.clone()));
        rows.push(Fig1Row {
            mass,
            harmonics: Some(h),
            iterations: s.iterations,
            seconds: s.solve_seconds,
            tip_min: s.stats.min,
            tip_max: s.stats.max,
            difference: (s.stats.min - reference.stats.min).abs() / reference.stats.min.abs(),
        });
    }
    let phase: Vec<f64> = reference.times.iter().map(|t| t / period).collect();
    series.push(Series::dashed(
        "reference (time marching)",
        phase.clone(),
        reference.tip.clone(),
    ));
    csv_columns.push(("t_over_T_reference".into(), phase));
    csv_columns.push(("u_tip_reference".into(), reference.tip.clone()));
    rows.push(Fig1Row {
        mass,
        harmonics: None,
        iterations: reference.iterations,
        seconds: reference.solve_seconds,
        tip_min: reference.stats.min,
        tip_max: reference.stats.max,
        difference: 0.0,
    });
    bar.finish_and_clear();
    write_figure(
        out,
        &format!("fig1_{name}_mass"),
        &PlotSpec {
            title: format!(
                "Fig. 1: rod tip over one period, gap 0.5, omega = omega_1 ({name} mass)"
            ),
            x_label: "t / T".into(),
            y_label: "u_tip".into(),
            log_log: false,
        },
        &series,
        &csv_columns,
    )?;
    Ok(rows)
}

/// The Fig. 1 table: mass, method, iterations, time, tip extremes, difference to the reference.
pub fn fig1_table(rows: &[Fig1Row]) -> String {
    let mut out = String::from(
        "Fig. 1: rod tip over one period (20 elements, gap 0.5, omega = omega_1, zeta = 0.01)\n",
    );
    out.push_str(&format!(
        "{:<11} {:<10} {:>6} {:>9} {:>11} {:>11} {:>11}\n",
        "mass", "method", "iter", "ms", "tip min", "tip max", "diff (min)"
    ));
    for r in rows {
        out.push_str(&format!(
            "{:<11} {:<10} {:>6} {:>9.2} {:>11.6} {:>11.6} {:>11.2e}\n",
            format!("{:?}", r.mass).to_lowercase(),
            r.harmonics
                .map(|h| format!("H = {h}"))
                .unwrap_or_else(|| "reference".into()),
            r.iterations,
            1e3 * r.seconds,
            r.tip_min,
            r.tip_max,
            r.difference
        ));
    }
    out
}

/// Default solver settings for SSN-HB with `h` harmonics.
pub fn default_settings(h: usize) -> SolverSettings {
    SolverSettings {
        method: Method::SsnHb,
        harmonics: h,
        time_samples: default_hb_time_samples(h),
        c: None,
        penalty_stiffness: None,
        linear_solver: Default::default(),
        max_iterations: 200,
        globalization: Default::default(),
        tolerance: 1e-10,
        steps_per_period: 2000,
        max_periods: 2000,
        march_tolerance: 1e-8,
        restitution: 0.0,
    }
}

/// One curve of the default run's Fig. 2.
#[derive(Debug, Clone)]
pub struct Fig2Curve {
    /// Gap (None: no contact, the linear rod).
    pub gap: Option<f64>,
    /// Points on the branch.
    pub points: usize,
    /// Fold frequencies, in units of omega_1.
    pub folds: Vec<f64>,
    /// Peak amplitude and its frequency (units of omega_1).
    pub peak: (f64, f64),
    /// Wall time of the sweep.
    pub seconds: f64,
    /// Whether the branch reached the end of the interval.
    pub converged: bool,
}

/// The sweep of the default run's Fig. 2: `omega/omega_1` in `[0.5, 2]`, steps twice the
/// scene defaults (`0.02`, at most `0.1`), up to 5000 points.
pub fn figure_2_sweep() -> crate::scene::SweepSettings {
    crate::scene::SweepSettings {
        step: 0.02,
        max_step: 0.1,
        max_points: 5000,
        ..crate::scene::SweepSettings::new(0.5, 2.0)
    }
}

/// Fig. 2 of the paper: `max |u_tip|` against omega/omega_1 on [0.5, 2] for gaps 0.25, 0.5,
/// 0.75 and the linear rod, SSN-HB with `harmonics` harmonics, by pseudo-arclength
/// continuation; writes `fig2_H<h>.svg` and `.csv` into `out`.
pub fn figure_2(out: &Path, harmonics: usize, quiet: bool) -> Result<Vec<Fig2Curve>, CliError> {
    use crate::rod::RodContact;
    let sweep = figure_2_sweep();
    let settings = default_settings(harmonics);
    let bar = progress_bar(4, &format!("Fig. 2 (H = {harmonics})"), quiet);
    let mut curves = Vec::new();
    let mut series = Vec::new();
    let mut columns: Vec<(String, Vec<f64>)> = Vec::new();
    for gap in [Some(0.25), Some(0.5), Some(0.75), None] {
        let spec = RodSpec {
            contacts: gap
                .map(|g| vec![RodContact { node: 20, gap: g }])
                .unwrap_or_default(),
            ..RodSpec::canonical()
        };
        let rod = build_rod(&spec).map_err(|e| CliError::BadInput(e.to_string()))?;
        let r = crate::sweep::frequency_response(&rod, &settings, &sweep, None)
            .map_err(|e| CliError::BadInput(e.to_string()))?;
        bar.inc(1);
        let ratio = r.omega_ratio();
        let label = gap
            .map(|g| format!("gap {g}"))
            .unwrap_or_else(|| "linear".into());
        let peak = r
            .peak()
            .map(|(i, a)| (a, ratio[i]))
            .unwrap_or((f64::NAN, f64::NAN));
        curves.push(Fig2Curve {
            gap,
            points: r.points(),
            folds: r.folds.iter().map(|w| w / rod.omega_1).collect(),
            peak,
            seconds: r.solve_seconds,
            converged: r.converged,
        });
        let key = label.replace(' ', "_");
        columns.push((format!("omega_ratio_{key}"), ratio.clone()));
        columns.push((format!("amplitude_{key}"), r.amplitude.clone()));
        series.push(if gap.is_some() {
            Series::new(label, ratio, r.amplitude)
        } else {
            Series::dashed(label, ratio, r.amplitude)
        });
    }
    bar.finish_and_clear();
    write_figure(
        out,
        &format!("fig2_H{harmonics}"),
        &PlotSpec {
            title: format!("Fig. 2: frequency response of the rod tip, H = {harmonics}"),
            x_label: "omega / omega_1".into(),
            y_label: "max over a period of |u_tip|".into(),
            log_log: false,
        },
        &series,
        &columns,
    )?;
    Ok(curves)
}

/// The default run (`ssn` without a subcommand): the paper's figures into `out`.
pub fn default_run(out: &Path, quiet: bool) -> Result<(), CliError> {
    prepare_directory(out)?;
    let start = Instant::now();
    let mut rows = figure_1(out, MassModel::Modified, quiet)?;
    rows.extend(figure_1(out, MassModel::Consistent, quiet)?);
    print!("{}", fig1_table(&rows));
    println!(
        "With the modified mass (massless contact node) harmonic balance converges to the \
         time-marching reference; with the consistent mass the reference depends on the impact \
         law (here restitution 0) and the two need not agree."
    );
    println!();
    let curves = figure_2(out, 5, quiet)?;
    println!("Fig. 2: frequency response max|u_tip| on omega/omega_1 in [0.5, 2], H = 5 (the paper's setting)");
    println!(
        "{:<8} {:>7} {:>11} {:>10} {:>22} {:>9}",
        "curve", "points", "peak", "at omega", "folds (omega/omega_1)", "ms"
    );
    for c in &curves {
        let folds: Vec<String> = c.folds.iter().map(|f| format!("{f:.4}")).collect();
        println!(
            "{:<8} {:>7} {:>11.6} {:>10.4} {:>22} {:>9.2}{}",
            c.gap
                .map(|g| format!("gap {g}"))
                .unwrap_or_else(|| "linear".into()),
            c.points,
            c.peak.0,
            c.peak.1,
            if folds.is_empty() {
                "none".to_string()
            } else {
                folds.join(", ")
            },
            1e3 * c.seconds,
            if c.converged { "" } else { "  (stopped early)" }
        );
    }
    println!(
        "Contact stiffens the rod: the peak moves to higher frequency and is bounded by the gap; \
         the branches fold over (the jump frequencies are the folds)."
    );
    println!(
        "\nWrote {} in {:.1} s.",
        out.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::folds_summary;

    #[test]
    fn few_folds_are_listed_and_many_are_summarised_by_count_and_range() {
        assert_eq!(folds_summary(&[], 2.0), "none");
        assert_eq!(folds_summary(&[2.1, 2.05], 2.0), "1.0500, 1.0250");
        let many: Vec<f64> = (0..20).map(|k| 2.0 + 0.001 * k as f64).collect();
        assert_eq!(
            folds_summary(&many, 2.0),
            "20 between 1.0000 and 1.0095 (first 1.0000, last 1.0095; all in --json)"
        );
    }
}
