//! The up-front work estimates against the work the runs count: a time march is estimated
//! by the periods its damping needs to settle (not by `solver.max_periods`), within a
//! stated factor of the periods the march counts; so a model of a couple of hundred dofs
//! marches under the default limit.

use serde_json::Value;
use ssn::scene::Scene;
use ssn::work::{counted_march_periods, scene_work, Workload};

#[path = "common/process.rs"]
mod process;

use process::{json_success, ssn};

/// A rod of 10 elements with modified mass, marched at 200 steps per period (the periods
/// to settle do not depend on the step), with `damping` and `extra` lines.
fn rod(damping: &str, omega_ratio: f64, gap: f64) -> String {
    format!(
        "[rod]\nelements = 10\nmass = \"modified\"\n[damping]\n{damping}\n[forcing]\n\
         amplitude = 0.04\nomega_ratio = {omega_ratio}\n[contact]\ngap = {gap}\n\
         [solver]\nmethod = \"march\"\nsteps_per_period = 200\n"
    )
}

/// The periods the march of `scene` counts (`ssn solve --json`: its time steps over the
/// steps per period).
fn marched_periods(dir: &std::path::Path, scene: &str) -> f64 {
    let file = dir.join("scene.toml");
    std::fs::write(&file, scene).expect("write the scene");
    let doc: Value = json_success(&ssn(&[
        "solve",
        file.to_str().expect("a UTF-8 path"),
        "--json",
        "-q",
    ]));
    assert_eq!(doc["converged"], true, "{doc}");
    doc["counters"]["time_steps"].as_f64().expect("time steps") / 200.0
}

#[test]
fn a_march_is_estimated_within_a_factor_two_of_the_periods_it_counts() {
    let dir = tempfile::tempdir().expect("temporary directory");
    // Without a stop (gap 100) the decay alone settles the march: measured 1.0 to 1.33
    // times the decay's periods. A stop dissipates too, so the march settles sooner:
    // within a factor 2 either way is what the estimate promises; every case counts
    // 50 to 1,300 periods, far below `max_periods` = 2000, which the old estimate took.
    let cases = [
        ("zeta = 0.003", 1.0, 100.0),
        ("zeta = 0.01", 0.8, 100.0),
        ("zeta = 0.01", 1.3, 100.0),
        ("zeta = 0.05", 1.0, 100.0),
        (
            "model = \"rayleigh\"\nalpha = 0.02\nbeta = 0.004",
            1.0,
            100.0,
        ),
        ("zeta = 0.01", 0.8, 0.5),
        ("zeta = 0.05", 1.3, 0.5),
    ];
    for (damping, ratio, gap) in cases {
        let text = rod(damping, ratio, gap);
        let scene = Scene::from_toml(&text, "scene.toml").expect("a valid scene");
        let estimated = counted_march_periods(&scene, &scene.solver, None);
        let counted = marched_periods(dir.path(), &text);
        assert!(
            (counted / 2.0..=2.0 * counted).contains(&estimated),
            "{damping}, {ratio} omega_1, gap {gap}: estimated {estimated} periods, counted \
             {counted}"
        );
    }
}

#[test]
fn a_march_of_two_hundred_dofs_fits_the_default_limit_and_an_undamped_one_is_bounded() {
    let text = |damping: &str| {
        format!(
            "[rod]\nelements = 200\nmass = \"modified\"\n{damping}[forcing]\namplitude = 0.04\n\
             [contact]\ngap = 0.5\n[solver]\nmethod = \"march\"\n"
        )
    };
    let damped = Scene::from_toml(&text("[damping]\nzeta = 0.01\n"), "s.toml").expect("scene");
    let work = scene_work(&damped, 200, 1, Workload::Solve);
    assert!(work.flops < ssn::limits::DEFAULT_WORK_LIMIT, "{work:?}");
    assert!(work.what.contains("about"), "{work:?}");
    // Without damping nothing bounds the settling but `max_periods`.
    let undamped = Scene::from_toml(&text(""), "s.toml").expect("scene");
    let periods = counted_march_periods(&undamped, &undamped.solver, None);
    assert_eq!(periods, undamped.solver.max_periods as f64);
}

#[test]
fn a_sweeps_stability_is_estimated_within_a_factor_three_of_the_phases_it_counts() {
    use semismooth_contact::stability::hb_stability;
    use ssn::work::STABILITY_FLOPS_PER_CUBED_STATE;
    // The strongly forced rod of 40 elements: the contact closes once a period over most
    // of the branch.
    let text = "[rod]\nelements = 40\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
                [forcing]\namplitude = 0.2\n[contact]\ngap = 0.5\n[solver]\nharmonics = 10\n\
                [sweep]\nomega_ratio_from = 0.8\nomega_ratio_to = 1.6\n";
    let scene = Scene::from_toml(text, "scene.toml").expect("a valid scene");
    let rod = semismooth_contact::rod::build_rod(&scene.rod).expect("the rod");
    let sweep = scene.sweep.as_ref().expect("a sweep");
    let response =
        semismooth_contact::sweep::frequency_response(&rod.structure, &scene.solver, sweep, None)
            .expect("the sweep runs");
    let n = rod.structure.model.dofs() as f64;
    // The library's count of each point's analysis: 10 d^3 per phase of the period and
    // 25 d^3 for the monodromy's eigenvalues, d = 2N at most.
    let phases: Vec<f64> = (response.points.iter().enumerate())
        .map(|(i, p)| {
            let settings = response.point_settings(&scene.solver, i);
            let s = hb_stability(&rod.structure.model, &settings, p.omega, &p.state)
                .expect("the stability of a point");
            s.phases as f64
        })
        .collect();
    let counted: Vec<f64> = (phases.iter())
        .map(|p| (10.0 * p + 25.0) * (2.0 * n).powi(3))
        .collect();
    let mean = counted.iter().sum::<f64>() / counted.len() as f64;
    let estimated = STABILITY_FLOPS_PER_CUBED_STATE * (2.0 * n).powi(3);
    assert!(
        (mean / 3.0..=3.0 * mean).contains(&estimated),
        "estimated {estimated:e} per point, counted {mean:e} on average"
    );
    // Every point counts at least the eigenvalues' 25 d^3, so the factor 3 above cannot
    // fail on one side (45 <= 3 x 25): the estimate's two phases per point are checked
    // against the points' own mean phase count (measured 1.74: the contact opens and
    // closes over most of the branch), between 1.5 and 2.
    let mean_phases = phases.iter().sum::<f64>() / phases.len() as f64;
    assert!(
        mean_phases > 1.5 && mean_phases <= 2.0,
        "mean phases per point {mean_phases}: {phases:?}"
    );
    let work = scene_work(&scene, 40, 1, Workload::Branch);
    assert!(work.what.contains("its stability"), "{work:?}");
}

#[test]
fn a_solve_on_a_contact_with_mass_is_counted_within_a_factor_two_of_its_factorizations() {
    use ssn::work::counted_solve_iterations;
    let dir = tempfile::tempdir().expect("temporary directory");
    let file = dir.path().join("scene.toml");
    // The paper's rod (20 elements, tip stop): plain Newton converges at low H and with
    // the massless tip; with the tip's mass it stagnates from H = 40 and smoothing takes
    // over with 4 to 6 times the iterations, one factorization each.
    for (mass, harmonics) in [
        ("consistent", 20),
        ("consistent", 40),
        ("consistent", 60),
        ("consistent", 80),
        ("modified", 40),
        ("modified", 80),
    ] {
        let text = format!(
            "[rod]\nelements = 20\nmass = \"{mass}\"\n[damping]\nzeta = 0.01\n[forcing]\n\
             amplitude = 0.04\n[contact]\ngap = 0.5\n[solver]\nharmonics = {harmonics}\n"
        );
        std::fs::write(&file, &text).expect("write the scene");
        let scene = Scene::from_toml(&text, "scene.toml").expect("a valid scene");
        let counted = counted_solve_iterations(&scene, 1, &scene.solver);
        let o = ssn(&[
            "solve",
            file.to_str().expect("a UTF-8 path"),
            "--json",
            "-q",
        ]);
        let doc = json_success(&o);
        let factorizations = doc["counters"]["factorizations"].as_f64().expect("a count");
        assert!(
            (factorizations / 2.0..=2.0 * factorizations).contains(&counted),
            "{mass} mass, H = {harmonics}: counted {counted}, factored {factorizations}"
        );
    }
}

/// The time steps `ssn compare`'s study marched: each march entry's steps per period times
/// the periods it ran (its `iterations`), and the reference's.
fn study_march_steps(text: &str) -> (f64, f64, String) {
    use semismooth_contact::solve::solve;
    use ssn::accuracy_cost::{accuracy_cost, REFERENCE_STEPS, REFERENCE_TOLERANCES};
    let scene = Scene::from_toml(text, "scene.toml").expect("a valid scene");
    let rod = semismooth_contact::rod::build_rod(&scene.rod).expect("the rod");
    let omega = scene.omega(rod.omega_1);
    let study = accuracy_cost(&rod.structure, omega, &scene.solver, None).expect("the study");
    let ladder: f64 = (study.entries.iter())
        .filter_map(|e| Some((e.setting.strip_prefix("steps=")?, e.iterations)))
        .map(|(steps, periods)| steps.parse::<f64>().expect("steps") * periods as f64)
        .sum();
    // The reference at its first tolerance (where it settles there: a massless contact).
    let (tolerance, periods) = REFERENCE_TOLERANCES[0];
    let marched = |steps: usize| {
        let settings = ssn::scene::SolverSettings {
            method: ssn::scene::Method::March,
            steps_per_period: steps,
            march_tolerance: tolerance,
            max_periods: periods,
            estimate_error: false,
            ..scene.solver.clone()
        };
        let s = solve(&rod.structure, omega, &settings, None).expect("the march runs");
        s.counters.time_steps as f64
    };
    let reference = if study.reference.description.starts_with("time marching") {
        marched(REFERENCE_STEPS) + marched(REFERENCE_STEPS / 2)
    } else {
        f64::NAN
    };
    (ladder, reference, study.reference.description)
}

#[test]
fn a_compare_is_estimated_at_no_less_than_the_time_steps_its_study_marches() {
    use ssn::work::compare_march_steps;
    // The paper's rod with the massless contact node (10 elements): every march settles
    // (the trapezoidal rule); the estimate counts the periods of the damping's decay, which
    // a stop at resonance shortens (measured: the study marched 0.2 to 0.3 of the count).
    let text = "[rod]\nelements = 10\nmass = \"modified\"\n[damping]\nzeta = 0.01\n[forcing]\n\
                amplitude = 0.04\n[contact]\ngap = 0.5\n";
    let scene = Scene::from_toml(text, "scene.toml").expect("a valid scene");
    let estimated = compare_march_steps(&scene, 1, None);
    let (ladder, reference, description) = study_march_steps(text);
    let counted = ladder + reference;
    assert!(
        (counted..=6.0 * counted).contains(&estimated),
        "estimated {estimated:e} steps, the study marched {ladder:e} + {reference:e} ({description})"
    );
    // The tip node with mass (consistent mass, 4 elements): the Moreau–Jean march chatters
    // and settles at neither tolerance; the estimate counts every march at its period
    // limit, which is what the study's marches of 128 steps and more ran.
    let text = text.replace("elements = 10\nmass = \"modified\"", "elements = 4");
    let scene = Scene::from_toml(&text, "scene.toml").expect("a valid scene");
    let estimated = compare_march_steps(&scene, 1, None);
    let (ladder, _, description) = study_march_steps(&text);
    assert!(description.starts_with("SSN-HB"), "{description}");
    let reference = (ssn::accuracy_cost::REFERENCE_STEPS * 3000) as f64;
    let counted = ladder + reference;
    assert!(
        (counted..=1.5 * counted).contains(&estimated),
        "estimated {estimated:e} steps, the study marched {ladder:e} + {reference:e}"
    );
}
