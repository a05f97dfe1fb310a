use super::*;

/// The shipped scene of the paper's Fig. 1: the canonical rod, SSN-HB with H = 20.
const CANONICAL: &str = include_str!("../../../scenes/paper_fig1.toml");

#[test]
fn canonical_scene_resolves_to_the_canonical_rod() {
    let scene = Scene::from_toml(CANONICAL, "canonical.toml").unwrap();
    assert_eq!(scene.rod, RodSpec::canonical());
    assert_eq!(scene.solver.method, Method::SsnHb);
    assert_eq!(scene.solver.harmonics, 20);
    assert_eq!(scene.solver.time_samples, 256);
}

#[test]
fn hb_time_sample_default_is_a_power_of_two_of_at_least_four_per_basis_function() {
    for (harmonics, samples) in [(1, 64), (5, 64), (10, 128), (100, 1024)] {
        assert_eq!(
            default_hb_time_samples(harmonics),
            samples,
            "H = {harmonics}"
        );
    }
}

#[test]
fn unknown_key_is_named() {
    let text = CANONICAL.replace("gap = 0.5", "gap = 0.5\ngapp = 1");
    let err = Scene::from_toml(&text, "x.toml").unwrap_err().to_string();
    assert!(err.contains("x.toml") && err.contains("gapp"), "{err}");
}

#[test]
fn too_few_time_samples_for_the_harmonics_are_rejected() {
    let text = CANONICAL.replace("harmonics = 20", "harmonics = 20\ntime_samples = 40");
    let err = Scene::from_toml(&text, "x.toml").unwrap_err().to_string();
    assert!(
        err.contains("solver.time_samples") && err.contains("40"),
        "{err}"
    );
}
