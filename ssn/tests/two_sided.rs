//! Two contacts on one dof from opposite sides (a two-sided clearance, backlash): the
//! cantilever of `scenes/beam_two_sided.toml` rattling between two stops, solved
//! by SSN-HB and time marching; the sign of a contact's row of `G` checked by mirror images.

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::{ContactDirection, InvalidModel, Structure};
use semismooth_contact::solve::Solution;
use ssn::scene::{default_hb_time_samples, Method, Scene};

mod common;

/// The shipped two-sided scene, with `edit` applied to its text.
fn beam(edit: impl Fn(String) -> String) -> (Scene, Structure) {
    let path = common::scenes_dir().join("beam_two_sided.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let scene = Scene::from_toml(&edit(text), &path).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    (scene, structure)
}

/// The scene's text with its contacts replaced by one stop on the pad (`direction`) and
/// the load amplitude set to `amplitude`.
fn only(direction: &'static str, amplitude: &'static str) -> impl Fn(String) -> String {
    move |t: String| {
        let start = t.find("[[contact.point]]").unwrap();
        let end = t.find("[output]").unwrap();
        let contact =
            format!("[[contact.point]]\ndof = 41\ngap = 0.04\ndirection = {direction}\n\n");
        let t = format!("{}{contact}{}", &t[..start], &t[end..]);
        t.replace("amplitude = 0.01", &format!("amplitude = {amplitude}"))
    }
}

/// `s` solved at `scene`'s frequency with its settings, `method` and `harmonics`.
fn solve(s: &Structure, scene: &Scene, method: Method, harmonics: usize) -> Solution {
    let mut settings = scene.solver.clone();
    settings.method = method;
    settings.harmonics = harmonics;
    settings.time_samples = default_hb_time_samples(harmonics);
    settings.steps_per_period = 2000;
    let omega = scene.omega(s.omega_1);
    let sol = semismooth_contact::solve(s, omega, &settings, None).unwrap();
    assert!(sol.converged(), "{method:?}: {}", sol.termination);
    sol
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn rattling_between_two_stops_ssn_hb_agrees_with_time_marching() {
    let (scene, s) = beam(|t| t);
    assert_eq!(s.model.contacts.len(), 2);
    assert_eq!(
        s.model.contacts[1].direction(),
        Some(ContactDirection::Negative)
    );
    let gap = s.model.contacts[0].gap;
    let march = solve(&s, &scene, Method::March, 20);
    // Both stops are hit (the tip passes +-gap by the pad's compliance).
    assert!(
        march.stats.max > gap && march.stats.min < -gap,
        "{:?}",
        march.stats
    );
    let march_forces: Vec<f64> = march.contact_forces.iter().map(|f| mean(f)).collect();
    assert!(march_forces.iter().all(|f| *f < 0.0), "{march_forces:?}");
    let mut errors = Vec::new();
    for h in [10, 20, 40] {
        let hb = solve(&s, &scene, Method::SsnHb, h);
        // A cos forcing and symmetric stops: the response has half-period symmetry
        // u(t + T/2) = -u(t), so the extremes are opposite and the two contacts carry the
        // same mean force (to the Newton tolerance).
        assert!(
            (hb.stats.max + hb.stats.min).abs() < 1e-9,
            "H = {h}: {} / {}",
            hb.stats.max,
            hb.stats.min
        );
        let forces: Vec<f64> = hb.contact_forces.iter().map(|f| mean(f)).collect();
        assert!(common::relative(forces[0], forces[1]) < 1e-8, "{forces:?}");
        let tip = common::relative(hb.stats.max, march.stats.max)
            .max(common::relative(hb.stats.min, march.stats.min));
        let force = common::relative(forces[0], march_forces[0])
            .max(common::relative(forces[1], march_forces[1]));
        errors.push((tip, force));
    }
    // Measured: tip extremes 1.5e-4 / 7.3e-5 / 2.7e-5 and mean forces 1.5e-2 / 3.5e-3 /
    // 1.1e-3 relative at H = 10 / 20 / 40 (march: 2000 steps per period, its two mean
    // forces equal to 4e-8): the truncation error falls with H. Bounds at twice these.
    let bounds = [(3e-4, 3e-2), (1.5e-4, 7e-3), (5.4e-5, 2.2e-3)];
    for ((tip, force), (bt, bf)) in errors.iter().zip(bounds) {
        assert!(*tip <= bt && *force <= bf, "{errors:?}");
    }
}

#[test]
fn an_obstacle_on_the_negative_side_mirrors_one_on_the_positive_side() {
    // One stop above with load f, against one stop below with load -f: u -> -u exactly.
    let (up_scene, up) = beam(only("1", "0.01"));
    let (down_scene, down) = beam(only("-1", "-0.01"));
    for method in [Method::SsnHb, Method::PenaltyHb, Method::March] {
        let a = solve(&up, &up_scene, method, 20);
        let b = solve(&down, &down_scene, method, 20);
        let mirrored: Vec<f64> = b.tip.iter().map(|v| -v).collect();
        let diff = common::max_abs_diff(&a.tip, &mirrored);
        assert!(diff < 1e-10, "{method:?}: {diff:e}");
        let (fa, fb) = (mean(&a.contact_forces[0]), mean(&b.contact_forces[0]));
        assert!(
            fa < 0.0 && common::relative(fa, fb) < 1e-9,
            "{method:?}: {fa} vs {fb}"
        );
        assert!(
            (a.stats.max_penetration - b.stats.max_penetration).abs() < 1e-12,
            "{method:?}"
        );
    }
}

#[test]
fn stops_on_one_side_twice_or_without_clearance_are_rejected() {
    let path = common::scenes_dir().join("beam_two_sided.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let same_side = text.replace("direction = -1", "direction = 1");
    let err = Scene::from_toml(&same_side, &path).unwrap_err().to_string();
    assert!(
        err.contains("contact.point.dof") && err.contains("41") && err.contains("opposite"),
        "{err}"
    );
    // Two stops on one dof without clearance: the scene names them when it is read.
    let closed = text.replacen("gap = 0.04", "gap = -0.04", 1);
    let err = Scene::from_toml(&closed, &path).unwrap_err().to_string();
    assert!(
        err.contains("contact.point.gap") && err.contains("clearance"),
        "{err}"
    );
    let (_, s) = beam(|t| t);
    let mut model = s.model.clone();
    model.contacts[1].gap = -0.04;
    assert!(matches!(
        model.validate(),
        Err(InvalidModel::NoClearance { first: 0, second: 1, dof: 40, clearance }) if clearance == 0.0
    ));
    // The periodic LCP says it does not take the negative side.
    let (scene, _) = beam(|t| t);
    let mut solver = scene.solver.clone();
    solver.method = Method::LcpLemke;
    let err = semismooth_contact::solve(&s, scene.omega(s.omega_1), &solver, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("negative side") && err.contains("dof 41"),
        "{err}"
    );
}
