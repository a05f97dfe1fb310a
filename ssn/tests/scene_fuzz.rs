//! Fuzzing the scene parser with proptest: arbitrary text, and mutations of a valid
//! scene, never panic; every rejection names the file.

use proptest::prelude::*;
use semismooth_contact::rod::build_rod;
use ssn::scene::Scene;

const BASE: &str = "[rod]\nelements = 20\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
[forcing]\namplitude = 0.04\nomega_ratio = 1.0\n[contact]\ngap = 0.5\n[solver]\nharmonics = 8\n";

fn check(text: &str) {
    match Scene::from_toml(text, "fuzz.toml") {
        Ok(scene) => {
            // A scene that validates must build (or be rejected by the builder with a
            // typed error), never panic.
            let _ = build_rod(&scene.rod);
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.toml"), "{e}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        check(&text);
    }

    #[test]
    fn byte_level_mutations_of_a_valid_scene_never_panic(
        position in 0usize..BASE.len(),
        replacement in "[-=\\[\\]\"a-z0-9.\\n ]{0,6}",
        cut in 0usize..8,
    ) {
        let mut text = BASE.to_string();
        let start = position.min(text.len());
        let end = (start + cut).min(text.len());
        text.replace_range(start..end, &replacement);
        check(&text);
    }

    #[test]
    fn numeric_values_in_any_range_never_panic(
        elements in -5i64..5000,
        gap in prop::num::f64::ANY,
        zeta in prop::num::f64::ANY,
        harmonics in -2i64..300,
        samples in -2i64..5000,
    ) {
        let text = format!(
            "[rod]\nelements = {elements}\n[damping]\nzeta = {zeta:?}\n[forcing]\namplitude = 0.1\n\
             [contact]\ngap = {gap:?}\n[solver]\nharmonics = {harmonics}\ntime_samples = {samples}\n"
        );
        check(&text.replace("NaN", "nan"));
    }
}
