//! Writes the matrices of a second structure, independent of the rod: an Euler–Bernoulli
//! cantilever beam (bending, two dofs per node) with a massless contact pad at its tip, as
//! Matrix Market files for a `[model]` scene (`scenes/beam/` and
//! `scenes/beam_tip_stop.toml` are its output for 20 elements).
//!
//! The beam is `semismooth_contact::structures::cantilever_with_tip_pad` (beam units
//! `L = EI = rhoA = 1`, Hermite-cubic elements, a massless pad on a spring at the tip,
//! a uniform unit load; see that module for the matrices and the analytic frequencies). In
//! the files (1-based) node `i` has the deflection dof `2i - 1` and the rotation dof `2i`;
//! the pad is dof `2n + 1`.
//!
//! `cargo run --release --example beam_matrices -- [ELEMENTS] [DIR]` (defaults 20 and
//! `scenes/beam`).

mod args;

use std::path::PathBuf;

use args::positional;
use semismooth_contact::matrix_market::model_matrix_files;
use semismooth_contact::structures::cantilever_with_tip_pad;

fn main() {
    let elements: usize = positional(1, 20, "ELEMENTS: a positive integer");
    assert!(elements >= 1, "ELEMENTS: a positive integer");
    let dir: PathBuf = positional(2, "scenes/beam".into(), "DIR: a directory");
    std::fs::create_dir_all(&dir).expect("output directory");
    let (k, m, f) = cantilever_with_tip_pad(elements);
    for (name, text) in model_matrix_files(&k, &m, &f) {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("writable output");
        println!("wrote {}", path.display());
    }
    println!(
        "{elements} elements, {} dofs: tip deflection dof {}, pad dof {} (1-based)",
        2 * elements + 1,
        2 * elements - 1,
        2 * elements + 1
    );
}
