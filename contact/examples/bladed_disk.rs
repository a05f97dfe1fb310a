//! Writes a structure with many contacts: a mistuned bladed disk whose blade tips rub a
//! casing, as Matrix Market files for a `[model]` scene (`scenes/blades/` and
//! `scenes/bladed_disk_casing.toml` are its output for 100 blades). The disk is
//! `semismooth_contact::structures::BladedDisk` with the shipped mistuning:
//!
//! `B` sectors in a ring; sector `j` has a disk dof `d_j` (dof `3j + 1`, 1-based) and a blade
//! tip dof `b_j` (dof `3j + 2`), both of unit mass, and a massless contact pad `p_j` (dof
//! `3j + 3`). Springs: `k_g = 1` from each disk dof to the ground, `k_d = 1` between
//! neighbouring disk dofs (cyclic), the blade `k_b (1 + delta_j)` between `d_j` and `b_j`
//! with `k_b = 1` and a deterministic mistuning `delta_j = 0.02 sin(2.3 j)` (so that the
//! blades do not all touch at the same instant), and the pad `k_c = 10` between `b_j` and
//! `p_j` (a free massless pad carries no force: the pads change no natural frequency, and
//! the contacts are well posed for every method). The load (`f.mtx`) is a unit force on
//! every blade tip, in phase (engine order 0); the casing is a stop on every pad (the
//! scene's `[[contact.point]]` list).
//!
//! `cargo run --release --example bladed_disk -- [BLADES] [DIR]` (defaults 100 and
//! `scenes/blades`); the scene's contact list is printed.

mod args;

use std::path::PathBuf;

use args::positional;
use semismooth_contact::matrix_market::model_matrix_files;
use semismooth_contact::structures::{BladedDisk, SHIPPED_MISTUNING};

fn main() {
    let blades: usize = positional(1, 100, "BLADES: a positive integer");
    assert!(blades >= 1, "BLADES: a positive integer");
    let dir: PathBuf = positional(2, "scenes/blades".into(), "DIR: a directory");
    std::fs::create_dir_all(&dir).expect("output directory");
    let (k, m, f) = BladedDisk {
        blades,
        mistuning: SHIPPED_MISTUNING,
    }
    .matrices();
    for (name, text) in model_matrix_files(&k, &m, &f) {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("writable output");
        eprintln!("wrote {}", path.display());
    }
    for j in 0..blades {
        println!("[[contact.point]]\ndof = {}\ngap = 1.0\n", 3 * j + 3);
    }
}
