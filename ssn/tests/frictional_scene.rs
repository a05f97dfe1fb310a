//! 3-D frictional contacts written in a `[model]` scene: a node with a unit `normal` (the
//! tangent plane completed by the program, or given), or three rows; solved by `ssn solve
//! --json`, which reports each contact's normal force, tangential force and dissipation.
//!
//! The structure is one node (three unit masses on unit springs, damping 0.05), pressed
//! along z by a static load 2 against an obstacle at `gap = 0.5` (normal force 1.5) and
//! driven in the plane by the rotating load `(cos w t, sin w t)`: it slides on a circle of
//! radius `r` with `((k - m w^2)^2 + c^2 w^2) r^2 + 2 c w b r + b^2 - F^2 = 0`
//! (`b = mu N`), and dissipates `2 pi mu N r` per cycle (no code of ours).

#[path = "common/process.rs"]
mod process;

use std::f64::consts::PI;
use std::path::PathBuf;

use process::{json_success, ssn};
use semismooth_contact::matrix_market::build_imported;
use ssn::scene::Scene;

const OMEGA: f64 = 1.3;
const MU: f64 = 0.3;
const NORMAL: f64 = 1.5;

/// A fresh directory holding the node's matrices, loads and dof map.
fn node_files(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssn-frictional-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let diagonal = |v: f64| {
        format!("%%MatrixMarket matrix coordinate real general\n3 3 3\n1 1 {v}\n2 2 {v}\n3 3 {v}\n")
    };
    let vector = |i: usize, v: f64| {
        format!("%%MatrixMarket matrix coordinate real general\n3 1 1\n{i} 1 {v}\n")
    };
    for (name, text) in [
        ("M.mtx", diagonal(1.0)),
        ("K.mtx", diagonal(1.0)),
        ("D.mtx", diagonal(0.05)),
        ("fc.mtx", vector(1, 1.0)),
        ("fs.mtx", vector(2, 1.0)),
        ("press.mtx", vector(3, 2.0)),
        ("nodes.dof", "7.1\n7.2\n7.3\n".to_string()),
    ] {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

/// The scene with `contact` as its `[[contact.point]]` body.
fn scene(dir: &std::path::Path, contact: &str) -> PathBuf {
    let text = format!(
        "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\ndamping = \"D.mtx\"\n\
         dof_map = \"nodes.dof\"\n\n[forcing]\nvector = \"fc.mtx\"\nvector_sin = \"fs.mtx\"\n\
         static = \"press.mtx\"\namplitude = 1.0\nomega = {OMEGA}\n\n[[contact.point]]\n\
         {contact}\n\n[solver]\nmethod = \"ssn-hb\"\nharmonics = 3\n"
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The first frictional contact of the JSON document of `ssn solve --json` on `scene`.
fn first_frictional_contact(scene: &std::path::Path) -> serde_json::Value {
    let args = ["solve", scene.to_str().unwrap(), "--json", "--quiet"];
    json_success(&ssn(&args))["frictional_contacts"][0].clone()
}

/// The radius of the sliding circle (module documentation).
fn circle_radius() -> f64 {
    let (w, b) = (OMEGA, MU * NORMAL);
    let a = (1.0 - w * w).powi(2) + (0.05 * w).powi(2);
    let half_linear = 0.05 * w * b;
    (-half_linear + (half_linear * half_linear - a * (b * b - 1.0)).sqrt()) / a
}

/// A node contact with a completed tangent plane, one with given tangents and one written
/// as rows give the same circle, and `ssn solve --json` reports its dissipation
/// `2 pi mu N r`, a constant normal force and a slip over the whole period.
#[test]
fn a_node_contact_in_a_scene_reports_the_circle_dissipation() {
    let dir = node_files("circle");
    let forms = [
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3",
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ntangents = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]\n\
         gap = 0.5\nfriction = 0.3",
        "dofs = [3]\ncoefficients = [1.0]\ngap = 0.5\nfriction = 0.3\ntangent_dofs = [1]\n\
         tangent_coefficients = [1.0]\ntangent2_dofs = [2]\ntangent2_coefficients = [1.0]",
    ];
    let expected = 2.0 * PI * MU * NORMAL * circle_radius();
    for form in forms {
        let path = scene(&dir, form);
        let point = first_frictional_contact(&path);
        let point = &point;
        let energy = point["dissipated_energy"].as_f64().unwrap();
        // Exact on the circle at any H: Newton's tolerance alone (1e-10 of the forces).
        assert!(
            (energy - expected).abs() < 1e-8 * expected,
            "{form}: {energy} against {expected}"
        );
        assert_eq!(point["slip_fraction"].as_f64(), Some(1.0), "{form}");
        assert_eq!(point["separated_fraction"].as_f64(), Some(0.0), "{form}");
        for f in point["normal_force"].as_array().unwrap() {
            assert!((f.as_f64().unwrap() + NORMAL).abs() < 1e-8, "{form}");
        }
        let t = point["tangential_force"].as_array().unwrap();
        let (x, y) = (t[0].as_array().unwrap(), t[1].as_array().unwrap());
        for (a, b) in x.iter().zip(y) {
            let magnitude = a.as_f64().unwrap().hypot(b.as_f64().unwrap());
            assert!(
                (magnitude - MU * NORMAL).abs() < 1e-8,
                "{form}: |lambda_t| = {magnitude}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `ssn solve --csv` on the circle scene writes each 3-D contact's forces and slip
/// velocities as columns, the tangential force of magnitude `mu N` on every row (the
/// closed form), and the text summary has the contact's line.
#[test]
fn the_csv_and_the_text_of_a_solve_carry_the_3d_contact() {
    let dir = node_files("csv");
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3",
    );
    let csv = dir.join("out.csv");
    let out = ssn(&[
        "solve",
        path.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let summary = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(summary.contains("3-D contact 1"), "{summary}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t1, t2) = (column("contact3d_1_t1"), column("contact3d_1_t2"));
    column("contact3d_1_v2");
    for row in lines.filter(|l| !l.is_empty()) {
        let values: Vec<f64> = row.split(',').map(|v| v.trim().parse().unwrap()).collect();
        // Exact on the circle: Newton's tolerance, and the CSV's printed digits.
        let magnitude = values[t1].hypot(values[t2]);
        assert!((magnitude - MU * NORMAL).abs() < 1e-6, "{row}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The circle scene marched in time (`method = "march"`, the node massive: Moreau–Jean
/// with the impact law on the normal row and the disk per step) settles on the same
/// circle: its normal force, slip fraction and dissipation against `2 pi mu N r`.
#[test]
fn the_circle_scene_marched_in_time_dissipates_two_pi_mu_n_r() {
    let dir = node_files("circle-march");
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3",
    );
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "method = \"ssn-hb\"\nharmonics = 3",
        "method = \"march\"\nsteps_per_period = 1000",
    );
    std::fs::write(&path, text).unwrap();
    let point = first_frictional_contact(&path);
    let expected = 2.0 * PI * MU * NORMAL * circle_radius();
    let energy = point["dissipated_energy"].as_f64().unwrap();
    // Moreau–Jean is first order here: the friction impulse acts on the end-of-step
    // velocity, and the node rests on the obstacle at the O(h) penetration of its landing
    // (the velocity-level impact law keeps it), which lowers N by O(h). Measured 1.7e-3
    // relative at 1000 steps per period; asserted 5e-3.
    assert!(
        (energy - expected).abs() < 5e-3 * expected,
        "{energy} against {expected}"
    );
    assert_eq!(point["slip_fraction"].as_f64(), Some(1.0));
    for f in point["normal_force"].as_array().unwrap() {
        assert!((f.as_f64().unwrap() + NORMAL).abs() < 5e-3 * NORMAL);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The circle scene with `tangential_stiffness = kt` (a 3-D Jenkins element: two massless
/// slider dofs behind springs `kt`) slides the node on a circle of radius `r` (its x
/// amplitude, `tip_max` with the output on node 7's first component) and dissipates
/// `2 pi mu N sqrt(r^2 - (mu N / kt)^2)`, below the rigid contact's `2 pi mu N r`.
#[test]
fn a_node_contact_with_tangential_stiffness_dissipates_the_jenkins_closed_form() {
    let dir = node_files("jenkins");
    let kt = 1.0;
    let path = scene(
        &dir,
        &format!(
            "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3\n\
             tangential_stiffness = {kt}"
        ),
    );
    let text = std::fs::read_to_string(&path).unwrap() + "\n[output]\nnode = 7\ncomponent = 1\n";
    std::fs::write(&path, text).unwrap();
    let args = ["solve", path.to_str().unwrap(), "--json", "--quiet"];
    let document = json_success(&ssn(&args));
    let r = document["tip_max"].as_f64().unwrap();
    let point = &document["frictional_contacts"][0];
    let energy = point["dissipated_energy"].as_f64().unwrap();
    let slip = MU * NORMAL;
    let expected = 2.0 * PI * slip * (r * r - (slip / kt).powi(2)).sqrt();
    // Exact at any H on the circle; r is the largest of the output samples of
    // r cos(w t + phi), within r (1 - cos(pi / samples)) of r: 1e-4 relative is ample.
    assert!(
        (energy - expected).abs() < 1e-4 * expected,
        "{energy} against {expected} (r = {r})"
    );
    assert!(energy < 2.0 * PI * slip * r);
    assert_eq!(point["slip_fraction"].as_f64(), Some(1.0));
    std::fs::remove_dir_all(&dir).ok();
}

/// A normal that is not a unit vector, tangents not orthogonal to it, a negative
/// coefficient, a second tangent parallel to the first and a method without the disk are
/// refused with the key and the value.
#[test]
fn a_bad_frame_or_coefficient_is_refused_with_its_key() {
    let dir = node_files("refusals");
    let cases = [
        (
            "node = 7\nnormal = [0.0, 0.0, 2.0]\ngap = 0.5\nfriction = 0.3",
            "contact.point.normal",
        ),
        (
            "node = 7\nnormal = [0.0, 0.0, 1.0]\ntangents = [[0.0, 0.6, 0.8], [1.0, 0.0, 0.0]]\n\
             gap = 0.5\nfriction = 0.3",
            "contact.point.tangents",
        ),
        (
            "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = -0.3",
            "contact.point.friction",
        ),
        (
            "dofs = [3]\ncoefficients = [1.0]\ngap = 0.5\nfriction = 0.3\ntangent_dofs = [1]\n\
             tangent_coefficients = [1.0]\ntangent2_dofs = [1]\ntangent2_coefficients = [2.0]",
            "contact.point.tangent2_coefficients",
        ),
        (
            "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3\n\
             tangential_stiffness = -10.0",
            "contact.point.tangential_stiffness",
        ),
    ];
    for (form, key) in cases {
        let path = scene(&dir, form);
        let message = match Scene::from_path(&path) {
            Err(e) => e.to_string(),
            Ok(s) => match build_imported(s.model.as_ref().unwrap()) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("accepted: {form}"),
            },
        };
        assert!(message.contains(key), "{form}: {message}");
    }
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3",
    );
    // (Penalty HB has the regularised vector law: the periodic LCP has no disk.)
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("ssn-hb", "lcp-lemke");
    let message = Scene::from_toml(&text, &path).unwrap_err().to_string();
    assert!(message.contains("solver.method"), "{message}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A moving obstacle in a scene: the node pressed (static 2, gap 0.5) on an obstacle whose
/// gap moves by `0.1 cos w t` and which slides past at `(2, 1)`, no other load (amplitude
/// 0). The friction force is `mu N(t) v / |v|`, `N = P - k gap(t) - c gap' - m gap''`, and
/// the energy `mu |v| N_0 T - mu int N (u' . v / |v|) dt` with `u` the linear response to
/// that force (the closed form of `contact/tests/frictional_contact.rs`, one harmonic).
#[test]
fn a_moving_obstacle_in_a_scene_drags_the_node_with_the_closed_form_energy() {
    let dir = node_files("moving");
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3\ngap_cos = [0.1]\n\
         sliding_velocity = [2.0, 1.0]",
    );
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("amplitude = 1.0", "amplitude = 0.0")).unwrap();
    let point = first_frictional_contact(&path);
    let point = &point;
    let expected = dragged_energy(2.0 - 0.5);
    let energy = point["dissipated_energy"].as_f64().unwrap();
    // Exact at any H: every sample of the laws is; Newton's tolerance alone.
    assert!(
        (energy - expected).abs() < 1e-8 * expected,
        "{energy} against {expected}"
    );
    assert_eq!(point["slip_fraction"].as_f64(), Some(1.0));
    std::fs::remove_dir_all(&dir).ok();
}

/// The same moving obstacle driving a scene with no `[forcing]` at all (no static press:
/// the obstacle preloads the node through the gap -1.5, `N_0 = 1.5`), its period from
/// `[obstacle] omega`: the same closed-form energy.
#[test]
fn a_scene_driven_by_its_moving_obstacle_alone_needs_no_forcing() {
    let dir = node_files("obstacle-only");
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = -1.5\nfriction = 0.3\ngap_cos = [0.1]\n\
         sliding_velocity = [2.0, 1.0]",
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let start = text.find("[forcing]").unwrap();
    let end = text.find("[[contact.point]]").unwrap();
    let text = format!(
        "{}[obstacle]\nomega = {OMEGA}\n\n{}",
        &text[..start],
        &text[end..]
    );
    std::fs::write(&path, text).unwrap();
    let point = first_frictional_contact(&path);
    let expected = dragged_energy(1.5);
    let energy = point["dissipated_energy"].as_f64().unwrap();
    // Exact at any H: Newton's tolerance alone.
    assert!(
        (energy - expected).abs() < 1e-8 * expected,
        "{energy} against {expected}"
    );
    // Without a moving obstacle a scene still needs its [forcing].
    let still = std::fs::read_to_string(&path)
        .unwrap()
        .replace("gap_cos = [0.1]\nsliding_velocity = [2.0, 1.0]", "");
    let message = Scene::from_toml(&still, &path).unwrap_err().to_string();
    assert!(message.contains("forcing"), "{message}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The energy per cycle of the node (unit mass and stiffness, damping 0.05) pressed with the
/// mean normal force `n0` on the obstacle whose gap moves by `0.1 cos w t` and which slides
/// at `(2, 1)`: `mu |v| N_0 T - mu int N (u' . v / |v|) dt`, `u` the linear response along
/// `v / |v|` to `mu N(t)` on harmonic 1.
fn dragged_energy(n0: f64) -> f64 {
    let (w, c, a1) = (OMEGA, 0.05, 0.1);
    let (nc, ns) = (-(1.0 - w * w) * a1, c * w * a1);
    let speed = 5f64.sqrt();
    // The scalar response along v / |v| to mu N(t) on harmonic 1 (unit m, k; damping c).
    let (kk, cw) = (1.0 - w * w, c * w);
    let det = kk * kk + cw * cw;
    let (uc, us) = (
        MU * (kk * nc - cw * ns) / det,
        MU * (cw * nc + kk * ns) / det,
    );
    let period = 2.0 * PI / w;
    let drag = 0.5 * period * (nc * w * us - ns * w * uc);
    MU * speed * n0 * period - MU * drag
}

/// `ssn scene-check` on a scene whose only contact is a 3-D node contact describes it (not
/// a linear problem), and the summary of `ssn solve` gives its normal force's mean: the
/// closed form `N = 1.5` (constant on the circle, to Newton's tolerance; printed to 7
/// digits).
#[test]
fn scene_check_describes_a_3d_contact_and_the_solve_summary_gives_its_mean_normal_force() {
    let dir = node_files("check");
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3",
    );
    let path = path.to_str().unwrap();
    let check = ssn(&["scene-check", path]);
    assert_eq!(check.status.code(), Some(0));
    let text = String::from_utf8_lossy(&check.stdout).to_string();
    assert!(!text.contains("linear problem"), "{text}");
    assert!(
        text.contains("contact 3-D") && text.contains("mu = 0.3"),
        "{text}"
    );
    let solve = ssn(&["solve", path]);
    assert_eq!(solve.status.code(), Some(0));
    let summary = String::from_utf8_lossy(&solve.stdout).to_string();
    assert!(
        summary.contains("normal force mean 1.500000e0"),
        "{summary}"
    );
}

/// `penalty-hb` solves a scene with a 3-D node contact by the regularised vector law: on the
/// circle (the slip speed `w r`, far above the default band) it is Coulomb's force, and the
/// energy is the closed form `2 pi mu N r` within the penalty's relative compliance
/// (`1 / k_p` of the default `1e5` times the contact stiffness: agreement within 1e-4).
#[test]
fn penalty_hb_on_a_3d_node_contact_dissipates_two_pi_mu_n_r() {
    let dir = node_files("penalty");
    let path = scene(
        &dir,
        "node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = 0.3",
    );
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("method = \"ssn-hb\"", "method = \"penalty-hb\"");
    std::fs::write(&path, text).unwrap();
    let contact = first_frictional_contact(&path);
    let energy = contact["dissipated_energy"].as_f64().unwrap();
    let expected = 2.0 * PI * MU * NORMAL * circle_radius();
    assert!(
        (energy - expected).abs() < 1e-4 * expected,
        "{energy} against {expected}"
    );
}
