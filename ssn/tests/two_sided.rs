//! Two contacts on one dof from opposite sides (a two-sided clearance, backlash): the
//! cantilever of `scenes/beam_two_sided.toml` rattling between two stops, solved
//! by SSN-HB and time marching; the sign of a contact's row of `G` checked by mirror images.

use semismooth_contact::model::{ContactDirection, InvalidModel, Structure};
use semismooth_contact::solve::Solution;
use ssn::scene::{default_hb_time_samples, Method, Scene};

mod common;

/// The shipped two-sided scene, with `edit` applied to its text.
fn beam(edit: impl Fn(String) -> String) -> (Scene, Structure) {
    common::shipped_model("beam_two_sided.toml", edit)
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
        let mirrored: Vec<f64> = b.observed.iter().map(|v| -v).collect();
        let diff = common::max_abs_diff(&a.observed, &mirrored);
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

/// A chain of nine unit masses and springs (fixed at its first dof) carrying a massless pad
/// on a stiff spring (1000) between two stops at +-0.01, with a third stop 0.02 ahead of
/// the mass that carries the pad, loaded there (amplitude 1, 2 % damping) at `omega_1`:
/// the stops share a load path but do not close together (the third closes at twice the
/// pad's static load).
fn pad_between_stops(dir: &std::path::Path, harmonics: usize) -> std::path::PathBuf {
    let n = 10;
    let mut k = format!("%%MatrixMarket matrix coordinate real symmetric\n{n} {n} 19\n");
    for i in 1..=9 {
        k += &format!("{i} {i} {}\n", if i == 9 { 1001.0 } else { 2.0 });
        if i < 9 {
            k += &format!("{} {i} -1\n", i + 1);
        }
    }
    k += "10 10 1000\n10 9 -1000\n";
    let mut m = format!("%%MatrixMarket matrix coordinate real general\n{n} {n} 9\n");
    for i in 1..=9 {
        m += &format!("{i} {i} 1\n");
    }
    let f = format!("%%MatrixMarket matrix coordinate real general\n{n} 1 1\n9 1 1\n");
    for (name, text) in [("K.mtx", k), ("M.mtx", m), ("f.mtx", f)] {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let scene = dir.join(format!("pad_h{harmonics}.toml"));
    std::fs::write(
        &scene,
        format!(
            "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n\
             [forcing]\nvector = \"f.mtx\"\namplitude = 1.0\nomega_ratio = 1.0\n\
             [[contact.point]]\ndof = 10\ngap = 0.01\n\
             [[contact.point]]\ndof = 10\ngap = 0.01\ndirection = -1\n\
             [[contact.point]]\ndof = 9\ngap = 0.02\n\
             [solver]\nharmonics = {harmonics}\n"
        ),
    )
    .unwrap();
    scene
}

/// Time marching of a loaded pad chain (an independent formulation in time), converged.
fn marched(loaded: &ssn::cli::Loaded) -> Solution {
    let mut settings = loaded.scene.solver.clone();
    settings.method = Method::March;
    let sol = semismooth_contact::solve(&loaded.structure, loaded.omega, &settings, None).unwrap();
    assert!(sol.converged(), "march: {}", sol.termination);
    sol
}

/// The mean force of the pad's two stops.
fn pad_force(s: &Solution) -> f64 {
    s.contacts[0].force_mean + s.contacts[1].force_mean
}

/// Stops that share a load path but close one after the other keep the default `c` of one
/// contact (10 x the static contact stiffness, 1.11 here): counted as sharing it was halved
/// to 0.56, where the solve from zero stagnated (measured: c from 0.05 to 0.8 failed in 4 of
/// 5 runs at H = 20). From zero with the default `c`, SSN-HB converges at H = 20 and 40 to
/// the orbit of time marching (an independent formulation in time): the mean force of the
/// pad's stops agrees within 1 % (measured 0.45 % and 0.35 %; HB's own change from H = 20 to
/// 40 is 0.1 %, the marcher's time step the rest), the third stop stays open in both.
#[test]
fn stops_on_one_load_path_that_close_one_after_the_other_converge_from_zero_with_the_default_c() {
    let dir = tempfile::tempdir().unwrap();
    let mut march = None;
    for harmonics in [20, 40] {
        let path = pad_between_stops(dir.path(), harmonics);
        let loaded = ssn::cli::load(&path).unwrap();
        let model = &loaded.structure.model;
        let static_stiffness = model.static_contact_stiffness().unwrap();
        assert!(
            (model.shared_contact_stiffness().unwrap() - static_stiffness).abs()
                < 1e-12 * static_stiffness,
            "the stops do not close together: no sharing"
        );
        let hb =
            semismooth_contact::solve(&loaded.structure, loaded.omega, &loaded.scene.solver, None)
                .unwrap();
        assert!(
            hb.converged(),
            "H = {harmonics}: {} after {} iterations",
            hb.termination,
            hb.iterations
        );
        let march = march.get_or_insert_with(|| marched(&loaded));
        let (a, b) = (pad_force(&hb), pad_force(march));
        assert!(
            a < 0.0 && common::relative(a, b) < 0.01,
            "H = {harmonics}: pad force {a} vs march {b}"
        );
        assert_eq!(hb.contacts[2].force_mean, 0.0, "the third stop stays open");
        assert_eq!(march.contacts[2].force_mean, 0.0);
    }
}

/// The default `c` on the pad chain: from zero it ends at the iteration limit at H = 30, 60
/// and 80 (measured, 200 iterations, residual 0.3-0.8), where 10 times it converges in
/// 41-69. The pad's dof is massless and tied to a mass by a spring of 1,000: at high
/// harmonics the mass no longer follows and the contact sees that spring, far above the
/// static stiffness (0.111) the default is scaled by. The solve then starts again with `c`
/// raised tenfold: the run converges, reports the raised `c` and counts the failed start's
/// iterations, and its orbit is time marching's (an independent formulation in time; the
/// pad's mean force within 1 %, as at H = 20 and 40).
#[test]
fn the_default_c_on_the_pad_chain_converges_at_h_30_and_60_through_a_raised_c_start() {
    let dir = tempfile::tempdir().unwrap();
    let mut march = None;
    for harmonics in [30, 60] {
        let path = pad_between_stops(dir.path(), harmonics);
        let loaded = ssn::cli::load(&path).unwrap();
        let structure = &loaded.structure;
        let default_c = structure.model.default_complementarity_constant();
        let settings = loaded.scene.solver.clone();
        let hb = semismooth_contact::solve(structure, loaded.omega, &settings, None).unwrap();
        assert!(
            hb.converged(),
            "H = {harmonics}: {} after {}",
            hb.termination,
            hb.iterations
        );
        assert_eq!(
            hb.c,
            Some(semismooth_contact::solve::RAISED_C_FACTOR * default_c),
            "H = {harmonics}: solved with the raised c"
        );
        assert!(
            hb.iterations > settings.max_iterations,
            "H = {harmonics}: the default c from zero converged in {} iterations: it no \
             longer needs the raised start",
            hb.iterations
        );
        let march = march.get_or_insert_with(|| marched(&loaded));
        let (a, b) = (pad_force(&hb), pad_force(march));
        assert!(
            a < 0.0 && common::relative(a, b) < 0.01,
            "H = {harmonics}: {a} vs {b}"
        );
    }
}
