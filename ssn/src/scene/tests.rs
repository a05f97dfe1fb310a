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

#[test]
fn an_override_gives_the_scene_of_the_edited_file() {
    let edited = CANONICAL
        .replace("gap = 0.5", "gap = 0.3")
        .replace("harmonics = 20", "harmonics = 40");
    let from_file = Scene::from_toml(&edited, "x.toml").unwrap();
    let overrides = [
        Override::parse("contact.gap=0.3").unwrap(),
        Override::parse("solver.harmonics=40").unwrap(),
    ];
    let overridden = Scene::from_toml_with(CANONICAL, "x.toml", &overrides).unwrap();
    assert_eq!(overridden, from_file);
}

#[test]
fn an_override_of_an_unknown_key_or_a_bad_value_is_refused_as_in_the_file() {
    let unknown = [Override::parse("contact.gapp=0.3").unwrap()];
    let err = Scene::from_toml_with(CANONICAL, "x.toml", &unknown)
        .unwrap_err()
        .to_string();
    assert!(err.contains("x.toml") && err.contains("gapp"), "{err}");
    let bad = [Override::parse("solver.harmonics=0").unwrap()];
    let err = Scene::from_toml_with(CANONICAL, "x.toml", &bad)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("solver.harmonics") && err.contains("1..=2000"),
        "{err}"
    );
    let wrong_type = [Override::parse("contact.gap=wide").unwrap()];
    let err = Scene::from_toml_with(CANONICAL, "x.toml", &wrong_type)
        .unwrap_err()
        .to_string();
    assert!(err.contains("contact.gap=\"wide\""), "{err}");
    assert!(Override::parse("no-equals-sign").is_err());
}

#[test]
fn a_bare_word_is_a_string_and_a_number_a_number() {
    assert_eq!(parse_value("ssn-hb"), toml::Value::String("ssn-hb".into()));
    assert_eq!(parse_value("40"), toml::Value::Integer(40));
    assert_eq!(parse_value("1.5"), toml::Value::Float(1.5));
    assert_eq!(
        parse_value("[1, 2]"),
        toml::Value::Array(vec![1.into(), 2.into()])
    );
}
