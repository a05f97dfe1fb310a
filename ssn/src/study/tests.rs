use std::path::Path;

use super::run::Shard;
use super::*;

const SCENE: &str = include_str!("../../../scenes/paper_fig1.toml");

fn study(text: &str) -> Result<Study, StudyError> {
    Study::from_toml(
        text,
        Path::new("study.toml"),
        &SceneSource::from_text(SCENE, "paper_fig1.toml"),
    )
}

fn value(case: &Case, key: &str) -> toml::Value {
    case.values
        .iter()
        .find(|o| o.key == key)
        .map(|o| o.value.clone())
        .unwrap_or_else(|| panic!("case {} sets no {key}", case.index))
}

#[test]
fn grid_points_run_with_the_first_key_slowest_then_the_listed_cases() {
    let s = study(
        "[grid]\n\"contact.gap\" = [0.3, 0.5]\n\"forcing.amplitude\" = [0.02, 0.04, 0.06]\n\
         [[case]]\n\"solver.harmonics\" = 5\n[[case]]\n\"solver.harmonics\" = 10\n",
    )
    .unwrap();
    assert_eq!(s.cases.len(), 2 * 3 * 2);
    assert_eq!(
        s.keys,
        ["contact.gap", "forcing.amplitude", "solver.harmonics"]
    );
    let expected: Vec<(f64, f64, i64)> = [0.3, 0.5]
        .iter()
        .flat_map(|&g| [0.02, 0.04, 0.06].map(|a| (g, a)))
        .flat_map(|(g, a)| [5, 10].map(|h| (g, a, h)))
        .collect();
    for (case, (g, a, h)) in s.cases.iter().zip(expected) {
        assert_eq!(value(case, "contact.gap"), toml::Value::Float(g));
        assert_eq!(value(case, "forcing.amplitude"), toml::Value::Float(a));
        assert_eq!(value(case, "solver.harmonics"), toml::Value::Integer(h));
    }
    assert!(s.cases.iter().enumerate().all(|(i, c)| c.index == i));
}

#[test]
fn random_samples_are_the_same_for_every_grid_point_and_depend_only_on_the_seed() {
    let text = "[grid]\n\"contact.gap\" = [0.3, 0.5]\n[random]\nsamples = 3\nseed = 5\n\
                [random.keys.\"damping.zeta\"]\ndistribution = \"uniform\"\nlow = 0.01\nhigh = 0.02\n";
    let s = study(text).unwrap();
    assert_eq!(s.cases.len(), 6);
    let zeta: Vec<toml::Value> = s.cases.iter().map(|c| value(c, "damping.zeta")).collect();
    assert_eq!(zeta[..3], zeta[3..]);
    assert_ne!(zeta[0], zeta[1]);
    assert_eq!(study(text).unwrap(), s);
    let other = study(&text.replace("seed = 5", "seed = 6")).unwrap();
    assert_ne!(other.cases[0].values, s.cases[0].values);
}

#[test]
fn normal_samples_have_the_mean_and_spread_asked_for() {
    // 5000 draws of N(0.04, 0.004^2): the sample mean is within 5 standard errors
    // (0.004 / sqrt(5000) = 5.7e-5) of 0.04, the sample standard deviation within 5 % of
    // 0.004 (its standard error is 1 / sqrt(2 x 5000) = 1 %).
    let s = study(
        "[random]\nsamples = 5000\nseed = 1\n[random.keys.\"forcing.amplitude\"]\n\
         distribution = \"normal\"\nmean = 0.04\nstd = 0.004\n",
    )
    .unwrap();
    let x: Vec<f64> = s
        .cases
        .iter()
        .map(|c| value(c, "forcing.amplitude").as_float().unwrap())
        .collect();
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let std = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    assert!((mean - 0.04).abs() < 5.0 * 0.004 / n.sqrt(), "{mean}");
    assert!((std / 0.004 - 1.0).abs() < 0.05, "{std}");
    // An unknown key is refused by the scene, naming it and the first case.
    let err = study(
        "[random]\nsamples = 2\nseed = 1\n[random.keys.\"forcing.vector_scale\"]\n\
         distribution = \"normal\"\nstd = 0.02\n",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("vector_scale") && err.contains("case 0"),
        "{err}"
    );
}

#[test]
fn a_list_drawn_for_a_number_key_is_refused_by_the_scene_naming_it() {
    let s = study(
        "[random]\nsamples = 2\nseed = 3\n[random.keys.\"contact.gap\"]\n\
         distribution = \"normal\"\nmean = 0.5\nstd = 0.01\nsize = 4\n",
    );
    // contact.gap is a number: a list is refused by the scene, naming the key.
    let err = s.unwrap_err().to_string();
    assert!(err.contains("contact.gap"), "{err}");
}

#[test]
fn shards_split_the_cases_round_robin_and_cover_each_case_once() {
    for count in 1..=5 {
        for case in 0..23 {
            let owners = (1..=count)
                .filter(|&index| Shard { index, count }.owns(case))
                .count();
            assert_eq!(owners, 1);
        }
    }
    assert_eq!(Shard::parse("3/8"), Ok(Shard { index: 3, count: 8 }));
    for bad in ["0/3", "4/3", "3", "a/b", "1/0"] {
        assert!(Shard::parse(bad).is_err(), "{bad}");
    }
}
