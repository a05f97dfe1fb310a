//! A new contact problem written against the public traits: a static chain of `N` nodes,
//! springs `k` between neighbours and `k_g` to the ground, pushed by forces towards two
//! rigid walls at gaps `g_l` (left of node 0) and `g_r` (right of node `N-1`).
//!
//! Unknowns `x = (u, l_l, l_r)`: `K u = f + l_l e_0 - l_r e_{N-1}`, with contact forces
//! `l >= 0` complementary to the gaps `u_0 + g_l >= 0` and `g_r - u_{N-1} >= 0`, written
//! as `min(l, c gap) = 0` (`c = k` turns length into force). Solved by the semismooth
//! Newton driver, then checked against Lemke on the condensed LCP in `z = (l_l, l_r)`:
//! `w = g + C K^{-1} (f + C^T z)`, `C = [e_0^T; -e_{N-1}^T]`.
//!
//! Run: `cargo run --release --example custom_problem` (exits non-zero if the two
//! answers differ by more than 1e-9; `tests/lemke.rs` runs the same comparison).

use semismooth::complementarity::min_function;
use semismooth::faer::Mat;
use semismooth::lemke::{solve_lcp, LemkeOptions};
use semismooth::linalg::FaerDenseLu;
use semismooth::polyalgorithm::{solve, PolyalgorithmOptions};
use semismooth::{EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, Residual};

/// The spring chain between two walls.
pub struct SpringChain {
    stiffness: Mat<f64>,
    force: Vec<f64>,
    gaps: [f64; 2],
    c: f64,
}

impl SpringChain {
    /// `n` nodes, springs `k` and `k_g`; the left half pushed left, the right half right.
    pub fn new(n: usize, k: f64, k_g: f64, load: f64, gaps: [f64; 2]) -> Self {
        let stiffness = Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 if i == 0 || i == n - 1 => k + k_g,
            0 => 2.0 * k + k_g,
            1 => -k,
            _ => 0.0,
        });
        let side = |i: usize| if i < n / 2 { -1.0 } else { 1.3 };
        let force = (0..n)
            .map(|i| load * side(i) / (1 + i % 3) as f64)
            .collect();
        Self {
            stiffness,
            force,
            gaps,
            c: k,
        }
    }
    /// The gaps `(u_0 + g_l, g_r - u_{N-1})` to the left and right walls.
    fn wall_gaps(&self, u: &[f64]) -> [f64; 2] {
        [u[0] + self.gaps[0], self.gaps[1] - u[u.len() - 1]]
    }
}

impl Residual for SpringChain {
    fn dim(&self) -> usize {
        self.force.len() + 2
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let n = self.force.len();
        let (u, l) = x.split_at(n);
        for (i, o) in out[..n].iter_mut().enumerate() {
            *o = (0..n).map(|j| self.stiffness[(i, j)] * u[j]).sum::<f64>() - self.force[i];
        }
        out[0] -= l[0];
        out[n - 1] += l[1];
        let g = self.wall_gaps(u);
        for w in 0..2 {
            out[n + w] = min_function(l[w], self.c * g[w]).value;
        }
        Ok(())
    }
}

impl GeneralizedJacobian for SpringChain {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.dim(), self.dim())
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        let n = self.force.len();
        jac.fill(0.0);
        jac.as_mut()
            .submatrix_mut(0, 0, n, n)
            .copy_from(&self.stiffness);
        (jac[(0, n)], jac[(n - 1, n + 1)]) = (-1.0, 1.0);
        let g = self.wall_gaps(&x[..n]);
        for (w, (node, dgap)) in [(0, 1.0), (n - 1, -1.0)].into_iter().enumerate() {
            let phi = min_function(x[n + w], self.c * g[w]);
            jac[(n + w, n + w)] = phi.da;
            jac[(n + w, node)] = phi.db * self.c * dgap;
        }
        Ok(())
    }
}

/// Solves the chain by Newton and by Lemke; returns both `x = (u, l_l, l_r)`.
pub fn newton_and_lemke(chain: &mut SpringChain) -> Result<[Vec<f64>; 2], String> {
    let n = chain.force.len();
    let mut x = vec![0.0; n + 2];
    let mut lu = FaerDenseLu::new();
    let report = solve(chain, &mut lu, &mut x, &PolyalgorithmOptions::default())
        .map_err(|e| e.to_string())?;
    if !report.converged() {
        return Err(format!("Newton did not converge: {}", report.termination));
    }
    // Condensed LCP: K^{-1} f, K^{-1} C_0^T (C_0^T = e_0), K^{-1} C_1^T (C_1^T = -e_{N-1}).
    lu.factor(&chain.stiffness).map_err(|e| e.to_string())?;
    let mut v = [chain.force.clone(), vec![0.0; n], vec![0.0; n]];
    (v[1][0], v[2][n - 1]) = (1.0, -1.0);
    for rhs in &mut v {
        lu.solve_in_place(rhs).map_err(|e| e.to_string())?;
    }
    let c = |y: &[f64]| [y[0], -y[n - 1]];
    let q: Vec<f64> = (0..2).map(|a| chain.gaps[a] + c(&v[0])[a]).collect();
    let m = Mat::from_fn(2, 2, |a, b| c(&v[1 + b])[a]);
    let lcp = solve_lcp(m.as_ref(), &q, &LemkeOptions::default()).and_then(|r| r.into_result());
    let z = lcp.map_err(|e| e.to_string())?.z;
    let mut y: Vec<f64> = (0..n)
        .map(|i| v[0][i] + z[0] * v[1][i] + z[1] * v[2][i])
        .collect();
    y.extend_from_slice(&z);
    Ok([x, y])
}

fn main() -> std::process::ExitCode {
    let mut worst = 0.0_f64;
    // Loads with both contacts open, only the right one closed, both closed.
    for load in [0.1, 0.3, 2.0] {
        let mut chain = SpringChain::new(12, 100.0, 1.0, load, [0.02, 0.05]);
        let [x, y] = match newton_and_lemke(&mut chain) {
            Ok(pair) => pair,
            Err(e) => {
                eprintln!("load {load}: {e}");
                return std::process::ExitCode::FAILURE;
            }
        };
        let diff = x
            .iter()
            .zip(&y)
            .fold(0.0_f64, |a, (p, q)| a.max((p - q).abs()));
        let n = x.len() - 2;
        println!(
            "load {load}: contact forces Newton ({:.10}, {:.10}), Lemke ({:.10}, {:.10}); max |difference| {diff:.1e}",
            x[n], x[n + 1], y[n], y[n + 1]
        );
        worst = worst.max(diff);
    }
    // Both methods are exact up to rounding on this well-conditioned 14-unknown problem.
    if worst > 1e-9 {
        eprintln!("Newton and Lemke disagree by {worst:e} > 1e-9");
        return std::process::ExitCode::FAILURE;
    }
    std::process::ExitCode::SUCCESS
}
