//! Writes the matrices of a second structure, independent of the rod: an Euler–Bernoulli
//! cantilever beam (bending, two dofs per node) with a massless contact pad at its tip, as
//! Matrix Market files for a `[model]` scene (`problems/scenes/beam/` and
//! `problems/scenes/beam_tip_stop.toml` are its output for 20 elements).
//!
//! Beam units: `L = EI = rhoA = 1`. `n` Hermite-cubic elements of length `h = 1/n`, node 0
//! clamped; node `i = 1..=n` has the deflection `w_i` (dof `2i - 1`, 1-based) and the
//! rotation `theta_i` (dof `2i`). Element matrices (dofs `w_a, theta_a, w_b, theta_b`):
//!
//! ```text
//! K_e = EI/h^3 [[12, 6h, -12, 6h], [6h, 4h^2, -6h, 2h^2], [-12, -6h, 12, -6h], [6h, 2h^2, -6h, 4h^2]]
//! M_e = rhoA h/420 [[156, 22h, 54, -13h], [22h, 4h^2, 13h, -3h^2], [54, 13h, 156, -22h],
//!                   [-13h, -3h^2, -22h, 4h^2]]
//! ```
//!
//! The natural frequencies converge to `(beta_k L)^2 sqrt(EI / (rhoA L^4))` with
//! `beta_k L = 1.8751, 4.6941, 7.8548, 10.9955, ...` (`cos(b) cosh(b) = -1`), at the rate
//! `h^4`. Dof `2n + 1` is a massless pad joined to the tip deflection by a spring
//! `k_c = 10 x 3 EI / L^3` (ten times the static tip stiffness); the stop acts on the pad.
//! A massless pad carries no force when free, so the beam's frequencies are unchanged, and
//! the contact is well posed for every method (no impact law needed). The load is a uniform
//! transverse load of unit intensity (consistent nodal forces and moments), `f.mtx`.
//!
//! `cargo run --release --example beam_matrices -- [ELEMENTS] [DIR]` (defaults 20 and
//! `problems/scenes/beam`).

use std::path::PathBuf;

use semismooth::faer::sparse::Triplet;
use semismooth_problems::import::{matrix_market_text, vector_market_text};
use semismooth_problems::model::SparseMatrix;

/// The pad's spring, relative to the static tip stiffness `3 EI / L^3`.
const PAD_STIFFNESS_FACTOR: f64 = 10.0;

/// Stiffness, mass and unit uniform load of the `elements`-element cantilever with a tip
/// pad (`2 elements + 1` dofs).
fn cantilever(elements: usize) -> (SparseMatrix, SparseMatrix, Vec<f64>) {
    let h = 1.0 / elements as f64;
    let n = 2 * elements + 1;
    let ke = {
        let c = 1.0 / (h * h * h);
        [
            [12.0, 6.0 * h, -12.0, 6.0 * h],
            [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
            [-12.0, -6.0 * h, 12.0, -6.0 * h],
            [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
        ]
        .map(|row| row.map(|v| c * v))
    };
    let me = {
        let c = h / 420.0;
        [
            [156.0, 22.0 * h, 54.0, -13.0 * h],
            [22.0 * h, 4.0 * h * h, 13.0 * h, -3.0 * h * h],
            [54.0, 13.0 * h, 156.0, -22.0 * h],
            [-13.0 * h, -3.0 * h * h, -22.0 * h, 4.0 * h * h],
        ]
        .map(|row| row.map(|v| c * v))
    };
    // Uniform load q = 1: nodal forces q h / 2 and moments +-q h^2 / 12.
    let fe = [h / 2.0, h * h / 12.0, h / 2.0, -h * h / 12.0];
    let (mut k, mut m) = (Vec::new(), Vec::new());
    let mut f = vec![0.0; n];
    for e in 0..elements {
        // Element e joins nodes e and e + 1; node i >= 1 has dofs 2(i - 1), 2(i - 1) + 1.
        let dofs: [Option<usize>; 4] = if e == 0 {
            [None, None, Some(0), Some(1)]
        } else {
            [
                Some(2 * e - 2),
                Some(2 * e - 1),
                Some(2 * e),
                Some(2 * e + 1),
            ]
        };
        for a in 0..4 {
            let Some(i) = dofs[a] else { continue };
            f[i] += fe[a];
            for b in 0..4 {
                let Some(j) = dofs[b] else { continue };
                k.push(Triplet::new(i, j, ke[a][b]));
                m.push(Triplet::new(i, j, me[a][b]));
            }
        }
    }
    let (tip, pad) = (2 * elements - 2, 2 * elements);
    let kc = PAD_STIFFNESS_FACTOR * 3.0;
    for (i, j, v) in [
        (tip, tip, kc),
        (tip, pad, -kc),
        (pad, tip, -kc),
        (pad, pad, kc),
    ] {
        k.push(Triplet::new(i, j, v));
    }
    let k = SparseMatrix::try_new_from_triplets(n, n, &k).expect("valid triplets");
    let m = SparseMatrix::try_new_from_triplets(n, n, &m).expect("valid triplets");
    (k, m, f)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let elements: usize = args
        .next()
        .map(|a| a.parse().expect("ELEMENTS: a positive integer"))
        .unwrap_or(20);
    assert!(elements >= 1, "ELEMENTS: a positive integer");
    let dir = PathBuf::from(args.next().unwrap_or_else(|| "problems/scenes/beam".into()));
    std::fs::create_dir_all(&dir).expect("output directory");
    let (k, m, f) = cantilever(elements);
    for (name, text) in [
        ("K.mtx", matrix_market_text(&k)),
        ("M.mtx", matrix_market_text(&m)),
        ("f.mtx", vector_market_text(&f)),
    ] {
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
