//! Frequency-response curves of the periodic LCP (method lcp-ssn: pseudo-arclength
//! continuation of `(w, z)` in the forcing frequency), checked against the SSN-HB branch at
//! high `H`, against plain min-map Newton re-solves at every branch point, and across two
//! `Nt` (the LCP's discretisation error must shrink at second order).

mod common;

use std::sync::OnceLock;

use common::{fig2_rod_model, sweep_fig2_interval};
use semismooth::continuation::ContinuationTermination;
use semismooth_contact::lcp::{ActiveSetSolver, PeriodicLcp, PeriodicLcpOptions};
use semismooth_contact::rod::{MassModel, RodModel};
use semismooth_contact::settings::{default_hb_time_samples, Method, SolverSettings};
use semismooth_contact::solve::RunError;
use semismooth_contact::sweep::{FrequencyResponse, SweepTermination};

fn settings(method: Method, harmonics: usize, time_samples: usize) -> SolverSettings {
    SolverSettings {
        time_samples,
        ..common::sweep_solver(method, harmonics)
    }
}

/// The canonical rod with the modified mass (massless contact node), gap 0.5, p0 = 0.04.
fn rod() -> &'static RodModel {
    static ROD: OnceLock<RodModel> = OnceLock::new();
    ROD.get_or_init(|| fig2_rod_model(Some(0.5), 0.04, MassModel::Modified))
}

/// The lcp-ssn branch over `[0.5, 2] omega_1` with `Nt` steps per period (computed once).
fn lcp_branch(nt: usize) -> &'static FrequencyResponse {
    static B128: OnceLock<FrequencyResponse> = OnceLock::new();
    static B256: OnceLock<FrequencyResponse> = OnceLock::new();
    let cell = match nt {
        128 => &B128,
        256 => &B256,
        _ => unreachable!("only Nt = 128, 256 are cached"),
    };
    cell.get_or_init(|| sweep_fig2_interval(rod(), &settings(Method::LcpSsn, 5, nt)).unwrap())
}

fn hb_branch(h: usize) -> FrequencyResponse {
    let s = settings(Method::SsnHb, h, default_hb_time_samples(h));
    let r = sweep_fig2_interval(rod(), &s).unwrap();
    assert!(r.converged(), "H = {h}: {}", r.termination);
    r
}

/// `(lowest fold, highest fold, peak amplitude)`: the jump-up and jump-down frequencies
/// of the overhang (in units of omega_1) and the largest tip amplitude.
fn summary(r: &FrequencyResponse) -> (f64, f64, f64) {
    let w1 = r.omega_1;
    let lo = r.folds.iter().copied().fold(f64::INFINITY, f64::min) / w1;
    let hi = r.folds.iter().copied().fold(f64::NEG_INFINITY, f64::max) / w1;
    (lo, hi, r.peak().unwrap().1)
}

#[test]
fn lcp_ssn_branch_passes_the_overhang_and_converges_to_the_ssn_hb_branch_at_second_order() {
    let rod = rod();
    let coarse = lcp_branch(128);
    let fine = lcp_branch(256);
    for (nt, r) in [(128, coarse), (256, fine)] {
        assert!(r.converged(), "Nt = {nt}: {}", r.termination);
        assert!((r.points.last().unwrap().omega / rod.omega_1 - 2.0).abs() < 1e-12);
        // The branch turns back at least once and ends going up: an even number of folds.
        assert!(r.folds.len() >= 2, "Nt = {nt}: {:?}", r.folds);
        assert_eq!(r.folds.len() % 2, 0, "Nt = {nt}");
        // Free response below the contact onset: the tip is at most at the gap there, and
        // the LCP's tip never passes the gap (w >= 0 node by node).
        let gap = 0.5;
        let excess = r
            .points
            .iter()
            .map(|p| p.observed_max)
            .fold(f64::NEG_INFINITY, |m, t| m.max(t - gap));
        assert!(
            excess <= 1e-9,
            "Nt = {nt}: tip beyond the gap by {excess:e}"
        );
    }
    let hb20 = hb_branch(20);
    let hb40 = hb_branch(40);
    let (s128, s256) = (summary(coarse), summary(fine));
    let (h20, h40) = (summary(&hb20), summary(&hb40));
    println!(
        "(lowest fold, highest fold, peak): Nt = 128 {s128:?} ({} folds), Nt = 256 {s256:?} \
         ({} folds), H = 20 {h20:?}, H = 40 {h40:?}",
        coarse.folds.len(),
        fine.folds.len()
    );
    // The trapezoidal rule warps harmonic k by (pi k / Nt)^2 / 3 (relative): 2.0e-4 k^2 at
    // Nt = 128, 5.0e-5 k^2 at Nt = 256. The response near the resonance is dominated by the
    // first few harmonics: the bound is the warping of harmonic k = 4 (3.2e-3 / 8.0e-4),
    // k = 5 for the peak amplitude (5.0e-3 / 1.3e-3: it is also sampled on the branch
    // points, about one percent of the resonant amplitude apart), plus the SSN-HB truncation
    // measured as |H40 - H20|. Measured relative differences to H = 40 at Nt = 128 / 256:
    // highest fold 1.2e-3 / 2.9e-4, peak 3.9e-3 / 6.7e-4, lowest fold 9.5e-4 / 8.5e-4.
    let warping = |nt: f64, k: f64| (std::f64::consts::PI * k / nt).powi(2) / 3.0;
    let relative = |a: f64, b: f64| ((a - b) / b).abs();
    for (what, pick, k) in [
        ("lowest fold", 0usize, 4.0),
        ("highest fold", 1, 4.0),
        ("peak amplitude", 2, 5.0),
    ] {
        let get = |s: (f64, f64, f64)| [s.0, s.1, s.2][pick];
        let hb_spread = relative(get(h20), get(h40));
        let d128 = relative(get(s128), get(h40));
        let d256 = relative(get(s256), get(h40));
        println!(
            "{what}: relative differences to H = 40: {d128:e} (Nt = 128), {d256:e} \
             (Nt = 256); H = 20 vs 40: {hb_spread:e}"
        );
        assert!(
            d128 <= warping(128.0, k) + hb_spread,
            "{what}: Nt = 128 {d128:e}"
        );
        assert!(
            d256 <= warping(256.0, k) + hb_spread,
            "{what}: Nt = 256 {d256:e}"
        );
        // The tolerance is meaningful: the difference is the LCP's discretisation error,
        // which shrinks like Nt^-2 (a factor 4 per doubling; at least 2.5 demanded). Not at
        // the lowest fold (jump-up at grazing contact), where SSN-HB itself converges
        // slowly and not monotonically in H (measured 1.01806 / 1.01857 / 1.01810 /
        // 1.01793 omega_1 at H = 20 / 40 / 80 / 120), while the LCP's (1.01760 / 1.01771 /
        // 1.01774 at Nt = 128 / 256 / 512) settles towards the H = 120 value.
        if pick != 0 {
            assert!(d256 <= d128 / 2.5, "{what}: {d128:e} -> {d256:e}");
        }
    }
}

#[test]
fn every_lcp_ssn_branch_point_is_a_fixed_point_of_min_map_newton() {
    let rod = rod();
    let r = lcp_branch(128);
    assert!(r.converged(), "{}", r.termination);
    let newton = common::plain_newton();
    let mut worst: f64 = 0.0;
    let mut worst_gap: f64 = 0.0;
    for (i, y) in r.points.iter().map(|p| &p.state).enumerate() {
        let options = PeriodicLcpOptions {
            time_samples: 128,
            ..Default::default()
        };
        let lcp = PeriodicLcp::new(&rod.model, r.points[i].omega, options).unwrap();
        let n = lcp.dim();
        assert_eq!(y.len(), 2 * n);
        let (w, z0) = y.split_at(n);
        // The gap half of the state is q + A z.
        let gap = lcp.gap(z0).unwrap();
        let scale = gap.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let dw = w
            .iter()
            .zip(&gap)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        worst_gap = worst_gap.max(dw / scale);
        // Corrector tolerance 1e-11 on |F|, entries of A of order 1: 1e-10 relative.
        assert!(
            dw <= 1e-10 * scale,
            "w = {}: gap off by {dw:e}",
            r.points[i].omega
        );
        let mut z = z0.to_vec();
        let mut problem = lcp.min_map();
        let mut solver = ActiveSetSolver::new().without_regularization();
        let what = format!("w = {}", r.points[i].omega);
        common::newton_converged(&what, &mut problem, &mut solver, &mut z, (&newton, None));
        let moved: f64 = z
            .iter()
            .zip(z0)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        // Relative to |z| (free points, z = 0: nothing may move beyond round-off).
        let size = z0.iter().map(|a| a * a).sum::<f64>().sqrt();
        if size > 0.0 {
            worst = worst.max(moved / size);
        }
        assert!(
            moved <= 1e-8 * size || moved <= 1e-14,
            "w = {}: moved {moved:e} (|z| = {size:e})",
            r.points[i].omega
        );
    }
    println!(
        "{} points: largest relative move of z {worst:e}, largest relative gap mismatch \
         {worst_gap:e}",
        r.points.len()
    );
}

#[test]
fn lcp_ssn_sweep_of_a_scene_without_contact_is_a_typed_error() {
    let linear = fig2_rod_model(None, 0.04, MassModel::Modified);
    let err = sweep_fig2_interval(&linear, &settings(Method::LcpSsn, 5, 128)).unwrap_err();
    assert!(matches!(
        err,
        RunError::Unsupported {
            method: "lcp-ssn",
            ..
        }
    ));
    assert!(err.to_string().contains("contact"), "{err}");
}

/// With the consistent mass (a massive contact node) the discrete LCP branch has a corner
/// right after the contact onset that the continuation cannot turn. The sweep must stop
/// there with the reason, not go back along the branch it came by (which it used to do,
/// down to `omega_from`, returning the branch twice).
#[test]
fn lcp_ssn_sweep_that_cannot_turn_a_corner_stops_with_a_reason_instead_of_going_back() {
    let rod = fig2_rod_model(Some(0.5), 0.04, MassModel::Consistent);
    let r = sweep_fig2_interval(&rod, &settings(Method::LcpSsn, 5, 128)).unwrap();
    println!(
        "{} points, last ratio {:.6}: {}",
        r.points.len(),
        r.omega_ratio().last().copied().unwrap_or(f64::NAN),
        r.termination
    );
    assert!(!r.converged());
    assert!(
        matches!(
            r.termination,
            SweepTermination::Branch(ContinuationTermination::Retraced { .. })
        ),
        "{}",
        r.termination
    );
    // Measured: it stalls at 0.982519 omega_1 after 40 points. A window of 0.005 around
    // it: a stall elsewhere (a regression) or passing the corner (an improvement, then
    // `converged`) is noticed.
    let stall = *r.omega_ratio().last().unwrap();
    assert!((stall - 0.982519).abs() <= 5e-3, "stalled at {stall}");
    // Up to the stall the frequency only increases (no fold before it on this branch, and
    // nothing of the way back is returned): the last point is the highest frequency.
    let ratios = r.omega_ratio();
    let last = *ratios.last().unwrap();
    assert!(ratios.iter().all(|&w| w <= last + 1e-12), "{ratios:?}");
    // The contact is active there (the stall is at a corner of the contact branch, past
    // the onset): the tip's maximum over the nodes is the gap (`u_tip = g - w`, `w = 0` at
    // a node in contact), to the corrector's tolerance.
    let tip_max = r.points.last().unwrap().observed_max;
    assert!((tip_max - 0.5).abs() < 1e-9, "{tip_max}");
}
