//! The shipped friction-damper scene (`scenes/friction_damper.toml`): its keys read and
//! checked, and its SSN-HB solution against the frictionless one in the limit of a vanishing
//! normal load.

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::Structure;
use semismooth_contact::solve::Solution;
use semismooth_contact::sweep::peak::PeakLocation;
use ssn::scene::Scene;

/// The shipped scene with `edit` applied to its text, or the error it gives.
fn scene(edit: impl Fn(String) -> String) -> Result<Scene, String> {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/friction_damper.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    Scene::from_toml(&edit(text), &path).map_err(|e| e.to_string())
}

/// The scene solved at its frequency (asserted converged), with its structure.
fn solve(scene: &Scene) -> (Structure, Solution) {
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    let omega = scene.omega(structure.omega_1);
    let solution = semismooth_contact::solve(&structure, omega, &scene.solver, None).unwrap();
    assert!(solution.converged(), "{}", solution.termination);
    (structure, solution)
}

#[test]
fn a_vanishing_normal_load_gives_the_frictionless_response() {
    // mu N = 5e-10 against a tip amplitude of 0.12 at resonance: the friction force moves
    // the response by about mu N / (2 zeta k_tip) ~ 1e-7 relative, below the 1e-6 asked.
    let slipping = scene(|t| t.replace("normal_load = 0.003", "normal_load = 1e-9")).unwrap();
    let frictionless = scene(|t| {
        let start = t.find("[[friction.point]]").unwrap();
        let end = t.find("[output]").unwrap();
        format!("{}{}", &t[..start], &t[end..])
    })
    .unwrap();
    let (s, with) = solve(&slipping);
    assert_eq!(s.model.friction.len(), 1);
    let (s0, without) = solve(&frictionless);
    assert!(s0.model.friction.is_empty());
    let peak = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let (a, a0) = (peak(&with.observed), peak(&without.observed));
    assert!((a - a0).abs() < 1e-6 * a0, "{a} vs {a0}");
    // The damper at its shipped load takes the resonance peak down (measured 0.0649 against
    // 0.1247 slipping freely).
    let (_, damped) = solve(&scene(|t| t).unwrap());
    assert!(
        peak(&damped.observed) < 0.6 * a0,
        "{} vs {a0}",
        peak(&damped.observed)
    );
}

#[test]
fn friction_keys_a_user_gets_wrong_are_named_with_what_is_allowed() {
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "friction = 0.5 ",
            "friction = -1.0 ",
            &["friction.point.friction", "-1", "mu >= 0"],
        ),
        (
            "normal_load = 0.003",
            "normal_load = 0.0",
            &["friction.point.normal_load", "0"],
        ),
        (
            "normal_load = 0.003",
            "",
            &["friction.point.normal_load", "missing"],
        ),
        (
            "coefficients = [1.0, -1.0]",
            "coefficients = [1.0]",
            &["friction.point.coefficients", "one coefficient per dof"],
        ),
        (
            "coefficients = [1.0, -1.0]",
            "coefficients = [0.0, 0.0]",
            &["friction.point.coefficients", "non-zero"],
        ),
        (
            "method = \"ssn-hb\"",
            "method = \"lcp-ssn\"",
            &["solver.method", "lcp-ssn", "ssn-hb", "penalty-hb"],
        ),
    ];
    for (from, to, words) in cases {
        let err = scene(|t| t.replace(from, to)).unwrap_err();
        for w in words {
            assert!(err.contains(w), "{to:?}: {err}");
        }
    }
    // A dof beyond the model is named when the files are read.
    let far = scene(|t| t.replace("dofs = [21, 42]", "dofs = [21, 43]")).unwrap();
    let err = build_imported(far.model.as_ref().unwrap())
        .unwrap_err()
        .to_string();
    assert!(err.contains("43") || err.contains("42"), "{err}");
}

#[test]
fn the_condensed_solve_of_the_damper_scene_is_the_full_one() {
    // The shipped scene (its H = 7, mu N = 1.5e-3, the pads sticking for part of the
    // period) by the full SSN-HB with the structured solve and by the SSN-HB condensed onto
    // its one friction row (15 force coefficients, dense LU), each from rest with the
    // smoothing polyalgorithm: the same root, to 1e-9 relative to the largest unknown
    // (Newton stops both at a residual below 1e-10 on the same equations).
    use semismooth::linalg::FaerDenseLu;
    use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
    use semismooth::Residual;
    use semismooth_contact::hb::{CondensedSsnHb, HbOptions, SsnHb, StructuredHbSolver};

    let scene = scene(|t| t).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    let omega = scene.omega(structure.omega_1);
    let options = HbOptions {
        harmonics: scene.solver.harmonics,
        ..HbOptions::default()
    };
    let newton = PolyalgorithmOptions::default();
    let mut full = SsnHb::new(&structure.model, omega, &options).unwrap();
    let mut x = vec![0.0; full.dim()];
    let report = solve_smoothing(&mut full, &mut StructuredHbSolver::new(), &mut x, &newton);
    assert!(report.unwrap().converged());
    let mut condensed = CondensedSsnHb::new(&structure.model, omega, &options).unwrap();
    let mut lambda = vec![0.0; condensed.dim()];
    let report = solve_smoothing(
        &mut condensed,
        &mut FaerDenseLu::new(),
        &mut lambda,
        &newton,
    );
    assert!(report.unwrap().converged());
    let expanded = condensed.expand(&lambda).unwrap();
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = x
        .iter()
        .zip(&expanded)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff < 1e-9 * scale, "{diff:e} of {scale:e}");
    // The friction force reaches its slip limit mu N (within the Gibbs overshoot of its
    // truncated series, as a square wave has 9 %).
    let force = full.contact_force_samples(&x, 0, 256).unwrap();
    let limit = 0.5 * 0.003;
    let largest = force.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    assert!(
        (largest - limit).abs() < 0.2 * limit,
        "{largest} vs {limit}"
    );
}

#[test]
fn a_friction_sweep_to_an_accuracy_changes_harmonics_with_the_friction_forces() {
    // The damper swept near its resonance with an accuracy target instead of harmonics: the
    // branch changes harmonics (48 down to 8 here), carrying the friction rows' forces with
    // the contact's. Each point is the solution at its own harmonics: a plain solve from zero
    // at its frequency and discretisation gives its extremes to 1e-8 relative (the Newton
    // tolerances of both runs).
    let scene = scene(|t| {
        t.replace("harmonics = 7", "accuracy = 1e-3")
            .replace("omega_ratio_from = 0.9", "omega_ratio_from = 0.97")
            .replace("omega_ratio_to = 1.3", "omega_ratio_to = 1.0")
    })
    .unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    let sweep = scene.sweep.as_ref().unwrap();
    let r = semismooth_contact::sweep::frequency_response(&structure, &scene.solver, sweep, None)
        .unwrap();
    assert!(r.converged(), "{}", r.termination);
    let harmonics: std::collections::BTreeSet<usize> =
        r.points.iter().filter_map(|p| p.harmonics).collect();
    assert!(
        harmonics.len() > 1,
        "one discretisation only: {harmonics:?}"
    );
    for (i, p) in r.points.iter().enumerate() {
        let at = r.point_settings(&scene.solver, i);
        let s = semismooth_contact::solve(&structure, p.omega, &at, None).unwrap();
        assert!(s.converged(), "{}", s.termination);
        let error = (s.stats.max - p.observed_max).abs() / s.stats.max.abs();
        assert!(
            error < 1e-8,
            "point {i} at H = {:?}: {error:e}",
            p.harmonics
        );
    }
}

#[test]
fn the_sweeps_peak_is_located_between_its_points_as_the_largest_plain_solve() {
    // The damper's branch points lie about 0.01 omega_1 apart near the peak, where the
    // largest point misses the peak by up to the curvature times that step squared. The
    // located peak must be the maximum of plain solves from zero on a grid 100 times finer
    // around it: at least as large as every one (1e-9: the solves' tolerance), and above the
    // largest within 1e-6 (half a grid step, 5e-5 omega_1, costs about (5e-5 / zeta)^2 / 2
    // ~ 1e-6 relative at zeta = 0.05).
    let scene = scene(|t| t).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    let sweep = scene.sweep.as_ref().unwrap();
    let r = semismooth_contact::sweep::frequency_response(&structure, &scene.solver, sweep, None)
        .unwrap();
    let peak = r.located_peak.clone().expect("a peak");
    assert_eq!(peak.location, PeakLocation::Located, "{peak:?}");
    let (i, largest_point) = r.peak().unwrap();
    assert!(peak.amplitude >= largest_point, "{peak:?} below point {i}");
    let omega_1 = structure.omega_1;
    let grid_max = (-20..=20)
        .map(|k| {
            let omega = peak.omega + k as f64 * 1e-4 * omega_1;
            let s = semismooth_contact::solve(&structure, omega, &scene.solver, None).unwrap();
            assert!(s.converged(), "{}", s.termination);
            s.stats.max.abs().max(s.stats.min.abs())
        })
        .fold(0.0f64, f64::max);
    assert!(
        peak.amplitude >= grid_max * (1.0 - 1e-9),
        "located {} below a grid solve {grid_max}",
        peak.amplitude
    );
    assert!(
        peak.amplitude <= grid_max * (1.0 + 1e-6),
        "located {} above the grid's largest {grid_max}",
        peak.amplitude
    );
}

#[test]
fn a_peak_beyond_the_window_is_reported_at_its_edge() {
    let scene = scene(|t| t.replace("omega_ratio_to = 1.3", "omega_ratio_to = 0.97")).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    let sweep = scene.sweep.as_ref().unwrap();
    let r = semismooth_contact::sweep::frequency_response(&structure, &scene.solver, sweep, None)
        .unwrap();
    let peak = r.located_peak.expect("a peak");
    assert_eq!(peak.location, PeakLocation::AtEdge);
    assert_eq!(peak.omega, r.points.last().unwrap().omega);
}
