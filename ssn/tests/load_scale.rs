//! The forced harmonic-balance solve's tolerance follows the load: the same scene in other
//! units (load and gap scaled together, a positively homogeneous problem whose response
//! scales by the same factor) converges at every scale to the same relative answer.

#[path = "common/process.rs"]
mod process;

use process::{json_success, ssn};

/// The modified-mass rod in other units: load 4e-5 and gap 5e-4 (the shipped 0.04 and 0.5
/// in thousandths), both times `scale`.
fn solve_at(scale: f64) -> serde_json::Value {
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes/paper_fig1_modified_mass.toml");
    let amplitude = format!("forcing.amplitude={:?}", 4e-5 * scale);
    let gap = format!("contact.gap={:?}", 5e-4 * scale);
    let args = [
        "solve",
        scene.to_str().unwrap(),
        "--json",
        "--quiet",
        "--set",
    ];
    json_success(&ssn(&[&args[..], &[&amplitude, "--set", &gap]].concat()))
}

/// Scales 1e-6, 1 and 1e6 all converge (exit 0, after at least one iteration: the zero
/// guess is no answer) and their tip extremes and mean contact force are the unit scale's
/// times the scale to 1e-8 relative: each solve balances at least six digits of its load,
/// and Newton ends quadratically on the same contact pieces (its last step leaves a
/// residual below 1e-12 of the load, measured), so the three agree far below 1e-8.
#[test]
fn responses_scale_linearly_with_load_and_gap_at_every_scale() {
    let unit = solve_at(1.0);
    for scale in [1e-6, 1.0, 1e6] {
        let run = solve_at(scale);
        assert_eq!(run["converged"], true, "scale {scale}: {run}");
        assert!(
            run["iterations"].as_u64().unwrap() > 0,
            "scale {scale}: {run}"
        );
        for key in ["tip_max", "tip_min", "contact_force_mean"] {
            let (x, y) = (unit[key].as_f64().unwrap(), run[key].as_f64().unwrap());
            assert!(x.abs() > 0.0, "{key} at unit scale: {unit}");
            assert!(
                (y / scale - x).abs() <= 1e-8 * x.abs(),
                "{key} at scale {scale}: {y} against {x} times the scale"
            );
        }
    }
}
