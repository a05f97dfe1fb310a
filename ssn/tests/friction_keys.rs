//! The friction keys of `[[contact.point]]` are honoured or refused, never dropped: on a
//! `[rod]` scene (whose contacts are stops on the axial displacement) each is refused
//! naming it; in a `[model]` scene a tangential row parallel to its normal row is refused,
//! and a row too small for its contact stiffness to be a number is refused naming the
//! coefficients (not the complementarity constant the user never set).

use std::path::Path;

#[path = "common/process.rs"]
mod process;

use process::ssn;

const K: &str = "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 2\n2 1 -1\n2 2 1\n";
const M: &str = "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1\n2 2 1\n";
const F: &str = "%%MatrixMarket matrix coordinate real general\n2 1 1\n2 1 1.0\n";

/// `ssn scene-check` of `scene` written in `dir` beside the 2-dof chain's matrices: its
/// exit code and standard error.
fn check(dir: &Path, scene: &str) -> (Option<i32>, String) {
    for (name, text) in [("K.mtx", K), ("M.mtx", M), ("f.mtx", F)] {
        std::fs::write(dir.join(name), text).expect("write a matrix");
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).expect("write the scene");
    let o = ssn(&["scene-check", path.to_str().expect("a UTF-8 path")]);
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

const ROD: &str =
    "[rod]\nelements = 10\n[forcing]\namplitude = 0.04\n[[contact.point]]\nnode = 10\n\
                   gap = 0.5\n";

#[test]
fn friction_keys_on_a_rod_contact_are_refused_naming_them() {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (line, key) in [
        ("friction = 0.3", "contact.point.friction"),
        ("tangent_dofs = [1]", "contact.point.tangent_dofs"),
        (
            "tangent_coefficients = [1.0]",
            "contact.point.tangent_coefficients",
        ),
        ("dofs = [1, 2]", "contact.point.dofs"),
        ("coefficients = [1.0, -1.0]", "contact.point.coefficients"),
    ] {
        let (code, message) = check(dir.path(), &format!("{ROD}{line}\n"));
        assert_eq!(code, Some(2), "{line}: {message}");
        assert!(
            message.contains(key) && message.contains("[rod]") && message.contains("`node`"),
            "{line}: {message}"
        );
    }
}

const MODEL: &str = "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n\
                     [forcing]\nvector = \"f.mtx\"\namplitude = 0.1\n[[contact.point]]\n\
                     dofs = [1, 2]\ncoefficients = [1.0, -1.0]\ngap = 0.05\n";

#[test]
fn a_tangential_row_parallel_to_its_normal_row_is_refused() {
    let dir = tempfile::tempdir().expect("temporary directory");
    for tangent in ["[1.0, -1.0]", "[-2.0, 2.0]", "[3e-5, -3e-5]"] {
        let scene = format!(
            "{MODEL}friction = 0.3\ntangent_dofs = [1, 2]\ntangent_coefficients = {tangent}\n"
        );
        let (code, message) = check(dir.path(), &scene);
        assert_eq!(code, Some(2), "{tangent}: {message}");
        assert!(
            message.contains("contact.point.tangent_coefficients") && message.contains("parallel"),
            "{tangent}: {message}"
        );
    }
    // An independent row is a tangent.
    let scene = format!(
        "{MODEL}friction = 0.3\ntangent_dofs = [1, 2]\ntangent_coefficients = [1.0, 1.0]\n"
    );
    let (code, message) = check(dir.path(), &scene);
    assert_eq!(code, Some(0), "{message}");
}

#[test]
fn a_row_too_small_for_a_contact_stiffness_is_refused_naming_its_coefficients() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let scene = MODEL.replace("[1.0, -1.0]", "[1e-300, -1e-300]");
    let (code, message) = check(dir.path(), &scene);
    assert_eq!(code, Some(2), "{message}");
    assert!(
        message.contains("contact.point.coefficients")
            && message.contains("norm")
            && !message.contains("invalid c "),
        "{message}"
    );
    // The same row scaled to 1e-50 is a contact.
    let scene = MODEL.replace("[1.0, -1.0]", "[1e-50, -1e-50]");
    let (code, message) = check(dir.path(), &scene);
    assert_eq!(code, Some(0), "{message}");
}
