//! Hard cases: each case is solved by SSN-HB and, where it applies, penalty HB and
//! the periodic LCP (Lemke, semismooth Newton), on the canonical rod with the modified mass
//! (massless contact node) unless said otherwise. Every run must either converge to a
//! physically plausible answer or end with a typed, non-converged outcome naming the reason;
//! never a panic, never NaN, never a hang (every solver has an iteration limit), and the same
//! bits when solved twice.
//!
//! Run with `cargo test --release --test hard_cases -- --nocapture` to print one table line
//! per case and method: `case | method | outcome | iterations | residual | tip min | penetration`.
//!
//! # Plausibility bounds
//!
//! - Harmonic balance: the contact condition holds in the Galerkin sense, so the truncated
//!   series can cross the gap. A tip with a velocity jump `Δv` at an impact has Fourier
//!   coefficients of amplitude `Δv / (π k² ω)`, whose tail beyond `H` sums to
//!   `Δv / (π ω H)`; with `Δv <= 2 ω A` (the velocity reversed, `A` the half peak-to-peak
//!   amplitude) the truncation error is at most `2 A / (π H)`. We allow twice that
//!   ([`hb_penetration_bound`]). Penalty HB adds its own penetration `max |λ| / k_p`.
//! - Periodic LCP: contact is exact at the time nodes up to the solver tolerance, so the
//!   penetration must be below `1e-9` (relative to the gap scale 1).
//! - Mean contact force `<= 0` (the obstacle only pushes), up to `1e-9 max |λ|` of rounding.

use std::panic::{catch_unwind, AssertUnwindSafe};

use semismooth_problems::cli::default_settings;
use semismooth_problems::hb::{HbOptions, SsnHb};
use semismooth_problems::rod::{
    build_rod, DampingSpec, FrequencySpec, MassModel, RodContact, RodModel, RodSpec,
};
use semismooth_problems::runner::{solve_rod, Solution};
use semismooth_problems::scene::{Method, Scene, SolverSettings, SweepSettings};
use semismooth_problems::sweep::frequency_response;

/// The canonical rod (paper Fig. 1) with the modified mass.
fn canonical() -> RodSpec {
    RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    }
}

fn with_gap(gap: f64) -> RodSpec {
    RodSpec {
        contacts: vec![RodContact { node: 20, gap }],
        ..canonical()
    }
}

/// SSN-HB settings with `H` harmonics (scene defaults, 200 iterations at most).
fn hb(h: usize) -> SolverSettings {
    default_settings(h)
}

fn with_method(method: Method, base: &SolverSettings) -> SolverSettings {
    let mut s = base.clone();
    s.method = method;
    if !method.is_harmonic_balance() {
        s.time_samples = 256;
    }
    s
}

const ALL: [Method; 4] = [
    Method::SsnHb,
    Method::PenaltyHb,
    Method::LcpLemke,
    Method::LcpSsn,
];
const HB_ONLY: [Method; 2] = [Method::SsnHb, Method::PenaltyHb];

/// Twice the truncation bound `2 A / (π H)` of a tip with a velocity jump (module docs).
fn hb_penetration_bound(s: &Solution) -> f64 {
    let h = s.harmonics.expect("HB solution") as f64;
    let half_amplitude = 0.5 * (s.stats.max - s.stats.min);
    2.0 * 2.0 * half_amplitude / (std::f64::consts::PI * h)
}

/// Outcome of one (case, method) run.
#[derive(Debug)]
enum Outcome {
    Converged(Solution),
    NotConverged(Solution),
    Error(String),
}

impl Outcome {
    /// One line: the termination and numbers, or the error (not the whole solution).
    fn summary(&self) -> String {
        match self {
            Outcome::Converged(s) | Outcome::NotConverged(s) => format!(
                "{} after {} iterations, residual {:e}, tip min {}",
                s.termination, s.iterations, s.residual_norm, s.stats.min
            ),
            Outcome::Error(e) => format!("error: {e}"),
        }
    }

    fn converged(&self) -> Option<&Solution> {
        match self {
            Outcome::Converged(s) => Some(s),
            _ => None,
        }
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| m.max(x.abs()))
}

fn print_row(case: &str, method: Method, outcome: &Outcome) {
    match outcome {
        Outcome::Converged(s) | Outcome::NotConverged(s) => println!(
            "HARD | {case:<34} | {:<10} | {:<28} | {:>5} | {:>9.2e} | {:>10.6} | {:>9.2e}",
            method.name(),
            if s.converged {
                "converged".to_string()
            } else {
                format!("NOT: {}", s.termination)
            },
            s.iterations,
            s.residual_norm,
            s.stats.min,
            s.stats.max_penetration
        ),
        Outcome::Error(e) => println!("HARD | {case:<34} | {:<10} | error: {e}", method.name()),
    }
}

/// Every reported number finite: the tip, the contact forces and the statistics (the
/// residual may be the only non-finite thing, and only for a non-converged run that says so).
fn assert_finite(case: &str, method: Method, s: &Solution) {
    let what = format!("{case} / {}", method.name());
    assert!(
        s.tip.iter().all(|v| v.is_finite()),
        "{what}: non-finite tip"
    );
    for f in &s.contact_forces {
        assert!(f.iter().all(|v| v.is_finite()), "{what}: non-finite force");
    }
    let st = &s.stats;
    for (name, v) in [
        ("max", st.max),
        ("min", st.min),
        ("max_penetration", st.max_penetration),
        ("mean_contact_force", st.mean_contact_force),
    ] {
        assert!(v.is_finite(), "{what}: {name} = {v}");
    }
    if s.converged {
        assert!(
            s.residual_norm.is_finite(),
            "{what}: residual {}",
            s.residual_norm
        );
    } else {
        assert!(!s.termination.is_empty(), "{what}: no termination reason");
        assert!(
            s.residual_norm.is_finite() || s.termination.contains("non-finite"),
            "{what}: residual {} with termination {}",
            s.residual_norm,
            s.termination
        );
    }
}

/// Physical plausibility of a converged answer (module docs).
fn assert_plausible(
    case: &str,
    method: Method,
    rod: &RodModel,
    settings: &SolverSettings,
    s: &Solution,
) {
    let what = format!("{case} / {}", method.name());
    let force_scale = s
        .contact_forces
        .iter()
        .map(|f| max_abs(f))
        .fold(0.0, f64::max);
    let bound = match method {
        Method::SsnHb => hb_penetration_bound(s),
        Method::PenaltyHb => {
            let kp = settings.penalty_stiffness.unwrap_or(
                semismooth_problems::scene::DEFAULT_RELATIVE_PENALTY
                    * rod.model.contact_stiffness_scale(),
            );
            hb_penetration_bound(s) + force_scale / kp
        }
        _ => 1e-9,
    };
    // The residual decreased from the initial guess (Newton methods keep the best iterate).
    if let (Some(first), Some(last)) = (s.residual_history.first(), s.residual_history.last()) {
        assert!(
            last <= first,
            "{what}: residual rose from {first:e} to {last:e}"
        );
    }
    assert!(
        s.stats.max_penetration <= bound,
        "{what}: penetration {:e} above the bound {bound:e}",
        s.stats.max_penetration
    );
    for (i, f) in s.contact_forces.iter().enumerate() {
        let mean = f.iter().sum::<f64>() / f.len().max(1) as f64;
        assert!(
            mean <= 1e-9 * force_scale.max(1e-300),
            "{what}: mean contact force {mean:e} > 0 at contact {i}"
        );
    }
}

/// Solves once under `catch_unwind`; a panic fails the test with the case named.
fn solve_once(case: &str, rod: &RodModel, settings: &SolverSettings) -> Result<Solution, String> {
    let run = catch_unwind(AssertUnwindSafe(|| solve_rod(rod, settings, None)));
    match run {
        Err(p) => {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!(
                "{case} / {}: the solver panicked: {msg}",
                settings.method.name()
            )
        }
        Ok(r) => r.map_err(|e| e.to_string()),
    }
}

/// Runs `method` on the case: solves twice (bitwise identical), checks finiteness and, when
/// converged, plausibility; prints the table line.
fn run(case: &str, spec: &RodSpec, base: &SolverSettings, method: Method) -> Outcome {
    let settings = with_method(method, base);
    let rod = build_rod(spec).unwrap_or_else(|e| panic!("{case}: rod: {e}"));
    let outcome = match solve_once(case, &rod, &settings) {
        Err(e) => {
            assert!(!e.is_empty(), "{case}: an error without a message");
            Outcome::Error(e)
        }
        Ok(s) => {
            assert_finite(case, method, &s);
            let again = solve_once(case, &rod, &settings)
                .unwrap_or_else(|e| panic!("{case}: second run failed: {e}"));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&s.tip),
                bits(&again.tip),
                "{case} / {}: tip differs run to run",
                method.name()
            );
            assert_eq!(
                s.residual_norm.to_bits(),
                again.residual_norm.to_bits(),
                "{case}: residual differs run to run"
            );
            assert_eq!(
                s.iterations, again.iterations,
                "{case}: iterations differ run to run"
            );
            let converged = s.converged;
            let outcome = if converged {
                Outcome::Converged(s)
            } else {
                Outcome::NotConverged(s)
            };
            print_row(case, method, &outcome);
            if let Outcome::Converged(s) = &outcome {
                assert_plausible(case, method, &rod, &settings, s);
            }
            return outcome;
        }
    };
    print_row(case, method, &outcome);
    outcome
}

fn run_all(case: &str, spec: &RodSpec, base: &SolverSettings, methods: &[Method]) -> Vec<Outcome> {
    methods.iter().map(|&m| run(case, spec, base, m)).collect()
}

/// When SSN-HB and Lemke both converged, their tip minima (away from the contact, where
/// the response is smooth) agree within the HB truncation bound plus the LCP's
/// first-order time discretisation, `ω A Δt` with `Δt = T / Nt` (one step of motion).
fn cross_check(case: &str, outcomes: &[Outcome], methods: &[Method]) {
    let find = |m: Method| {
        methods
            .iter()
            .position(|&x| x == m)
            .and_then(|i| outcomes[i].converged())
    };
    if let (Some(hb), Some(lcp)) = (find(Method::SsnHb), find(Method::LcpLemke)) {
        let a = 0.5 * (hb.stats.max - hb.stats.min);
        let dt_motion =
            hb.omega * a * (2.0 * std::f64::consts::PI / hb.omega) / lcp.time_samples as f64;
        let tol = hb_penetration_bound(hb) + dt_motion;
        let diff = (hb.stats.min - lcp.stats.min).abs();
        println!("HARD | {case:<34} | cross-check ssn-hb vs lcp-lemke tip min: diff {diff:.2e} (tol {tol:.2e})");
        assert!(
            diff <= tol,
            "{case}: SSN-HB tip min {} vs Lemke {} (diff {diff:e} > {tol:e})",
            hb.stats.min,
            lcp.stats.min
        );
    }
    if let (Some(e), Some(p)) = (find(Method::SsnHb), find(Method::PenaltyHb)) {
        // Same harmonics and quadrature; both within the truncation bound of the exact
        // periodic answer, the penalty also within its own penetration max|λ| / k_p.
        let tol = hb_penetration_bound(e) + hb_penetration_bound(p) + p.stats.max_penetration;
        let diff = (e.stats.min - p.stats.min).abs();
        println!("HARD | {case:<34} | cross-check ssn-hb vs penalty-hb tip min: diff {diff:.2e} (tol {tol:.2e})");
        assert!(
            diff <= tol,
            "{case}: SSN-HB tip min {} vs penalty {}",
            e.stats.min,
            p.stats.min
        );
    }
    if let (Some(a), Some(b)) = (find(Method::LcpLemke), find(Method::LcpSsn)) {
        // Same LCP, two solvers: the solution of a P-matrix LCP is unique; 1e-8 of the
        // amplitude covers the Newton tolerance 1e-10 on the forces times the compliance.
        let diff = (a.stats.min - b.stats.min).abs();
        assert!(
            diff <= 1e-8 * (1.0 + a.stats.min.abs()),
            "{case}: Lemke {} vs LCP-SSN {}",
            a.stats.min,
            b.stats.min
        );
    }
}

#[test]
fn light_damping_zeta_1e_4() {
    let spec = RodSpec {
        damping: Some(DampingSpec::StiffnessProportional { zeta: 1e-4 }),
        ..canonical()
    };
    let out = run_all("zeta = 1e-4", &spec, &hb(20), &ALL);
    cross_check("zeta = 1e-4", &out, &ALL);
}

/// No damping at all, forced exactly at `omega_1`: the linear part is singular in the first
/// harmonic, only the contact bounds the response. Any outcome is acceptable if clean (the
/// table shows which); the messages carry no NaN.
#[test]
fn undamped_at_resonance() {
    let spec = RodSpec {
        damping: None,
        ..canonical()
    };
    let out = run_all("undamped, omega_1", &spec, &hb(20), &ALL);
    cross_check("undamped, omega_1", &out, &ALL);
    for (m, o) in ALL.iter().zip(&out) {
        assert!(
            !o.summary().contains("NaN"),
            "{}: {}",
            m.name(),
            o.summary()
        );
    }
}

/// What the library should do: SSN-HB solves the undamped resonant rod that LCP-SSN solves
/// (tip min -0.529806, 22 iterations). From zero no contact is active, so the first
/// Jacobian is the undamped dynamic stiffness at `omega_1`, singular in the first harmonic;
/// SSN-HB (structured solver) stops after 1 iteration with `singular-jacobian` (pivot 5.7
/// against 1.4e15, index 820), penalty HB likewise after 6. Lemke ends on a ray after 2
/// pivots (A not copositive: symmetric-part eigenvalue -8.0e3).
#[test]
#[ignore = "reason: undamped canonical rod at omega_1: SSN-HB ends singular-jacobian after 1 iteration (the linear part is singular before contact activates); LCP-SSN converges to tip min -0.529806"]
fn undamped_at_resonance_converges_with_ssn_hb() {
    let spec = RodSpec {
        damping: None,
        ..canonical()
    };
    let hb_out = run("undamped, omega_1", &spec, &hb(20), Method::SsnHb);
    let lcp_out = run("undamped, omega_1", &spec, &hb(20), Method::LcpSsn);
    let e = hb_out
        .converged()
        .expect("SSN-HB converges undamped at omega_1");
    let l = lcp_out
        .converged()
        .expect("LCP-SSN converges undamped at omega_1");
    let a = 0.5 * (e.stats.max - e.stats.min);
    let tol = hb_penetration_bound(e) + 2.0 * std::f64::consts::PI * a / l.time_samples as f64;
    assert!(
        (e.stats.min - l.stats.min).abs() <= tol,
        "SSN-HB {} vs LCP-SSN {}",
        e.stats.min,
        l.stats.min
    );
}

#[test]
fn grazing_gap_zero() {
    let out = run_all("gap = 0", &with_gap(0.0), &hb(20), &ALL);
    cross_check("gap = 0", &out, &ALL);
    for o in &out {
        assert!(
            o.converged().is_some(),
            "gap 0 should converge: {}",
            o.summary()
        );
    }
}

#[test]
fn grazing_gap_1e_6() {
    let out = run_all("gap = 1e-6", &with_gap(1e-6), &hb(20), &ALL);
    cross_check("gap = 1e-6", &out, &ALL);
}

#[test]
fn preloaded_contact_negative_gap() {
    // Lemke is checked separately below (its accuracy here is the open question).
    let methods = [Method::SsnHb, Method::PenaltyHb, Method::LcpSsn];
    let out = run_all("gap = -0.1 (preload)", &with_gap(-0.1), &hb(20), &methods);
    cross_check("gap = -0.1 (preload)", &out, &methods);
    // Preloaded: the mean contact force is strictly compressive, and at least the static
    // preload: the rod pushed back by 0.1 over its length needs EA/L * 0.1 = 0.1.
    for s in out.iter().filter_map(Outcome::converged) {
        assert!(
            s.stats.mean_contact_force <= -0.1 * (1.0 - 1e-6),
            "{}: mean force {}",
            s.method.name(),
            s.stats.mean_contact_force
        );
    }
    assert!(
        out[0].converged().is_some(),
        "SSN-HB must converge on the preload"
    );
}

/// Lemke on the preloaded rod (contact active the whole period, 1666 pivots) reports
/// "Solved" with a complementarity error of 2.06e-9 (penetration 2.06e-9), where the
/// semismooth Newton on the same LCP reaches 2.6e-14: accuracy is lost along the long
/// pivot path.
#[test]
fn preloaded_contact_lemke_is_accurate() {
    let out = run(
        "gap = -0.1 (preload)",
        &with_gap(-0.1),
        &hb(20),
        Method::LcpLemke,
    );
    let s = out.converged().expect("Lemke solves the preloaded LCP");
    assert!(
        s.residual_norm <= 1e-9,
        "complementarity error {:e}",
        s.residual_norm
    );
}

/// Preloaded tip (gap -0.1) forced at `2 ω_1`, periodic LCP at `Nt = 32` (and 64): the
/// free response (amplitude 0.008) never leaves the obstacle, so at `z = 0` every row of the
/// min-map Jacobian is a row of `A`, and `A` is numerically singular there (last pivot
/// 5e-16 of the largest, at index `Nt - 1`). LCP-SSN stops at iteration 0 with
/// `singular-jacobian`; Lemke solves the same LCP (25 pivots, tip min -0.111544). At
/// `Nt = 128, 256` both converge. The semismooth solver should not give up on a singular
/// first Jacobian when the LCP has a solution.
#[test]
fn preloaded_lcp_ssn_survives_a_singular_first_jacobian() {
    let spec = RodSpec {
        frequency: FrequencySpec::Ratio(2.0),
        ..with_gap(-0.1)
    };
    let mut base = hb(20);
    base.method = Method::LcpSsn;
    base.time_samples = 32;
    let rod = build_rod(&spec).unwrap();
    let ssn = solve_once("preload, 2 omega_1, Nt 32", &rod, &base).unwrap();
    base.method = Method::LcpLemke;
    let lemke = solve_once("preload, 2 omega_1, Nt 32", &rod, &base).unwrap();
    assert!(lemke.converged, "Lemke: {}", lemke.termination);
    assert!(ssn.converged, "LCP-SSN: {}", ssn.termination);
    // Same LCP, unique solution: the tips agree to the solvers' tolerance.
    assert!((ssn.stats.min - lemke.stats.min).abs() <= 1e-8);
}

#[test]
fn forcing_ten_times_canonical() {
    let spec = RodSpec {
        amplitude: 0.4,
        ..canonical()
    };
    let out = run_all("forcing x10", &spec, &hb(20), &ALL);
    cross_check("forcing x10", &out, &ALL);
}

#[test]
fn many_harmonics_h100_nt4096() {
    let mut s = hb(100);
    s.time_samples = 4096;
    // The periodic LCP at 4096 steps is a dense 4096 x 4096 problem: not run here.
    let out = run_all("H = 100, Nt = 4096", &canonical(), &s, &HB_ONLY);
    cross_check("H = 100, Nt = 4096", &out, &HB_ONLY);
}

fn two_thousand_element_rod() -> RodSpec {
    RodSpec {
        elements: 2000,
        contacts: vec![RodContact {
            node: 2000,
            gap: 0.5,
        }],
        ..canonical()
    }
}

/// 2,000 elements. The default `c` was `K[tip, tip] = EA / h` (2000 here, 100 times the
/// 20-element value), with which SSN-HB stopped at max-iterations (200, residual 4.6e-4);
/// it is now 10 times the static contact stiffness `EA / L` whatever the mesh. With
/// `c = EA / L = 1` SSN-HB converges too, and its tip minimum agrees with the 20-element rod
/// within the HB truncation bound (the FE error of the smooth part, O(h²) = 2.5e-3 at 20
/// elements, is below it). Penalty HB and LCP-SSN may end non-converged (reported cleanly).
#[test]
fn two_thousand_elements() {
    let spec = two_thousand_element_rod();
    let methods = [Method::SsnHb, Method::PenaltyHb, Method::LcpSsn];
    run_all("2000 elements", &spec, &hb(20), &methods);
    let mut s = hb(20);
    s.c = Some(1.0);
    let fine = run("2000 elements, c = EA/L = 1", &spec, &s, Method::SsnHb);
    let fine = fine
        .converged()
        .expect("2000 elements with c = 1 converges");
    let coarse = run(
        "gap = 0.5 (reference, 20 el.)",
        &canonical(),
        &hb(20),
        Method::SsnHb,
    );
    let coarse = coarse.converged().expect("the canonical case converges");
    let tol = hb_penetration_bound(coarse);
    assert!(
        (fine.stats.min - coarse.stats.min).abs() <= tol,
        "2000 el. {} vs 20 el. {}",
        fine.stats.min,
        coarse.stats.min
    );
}

/// What the library should do: the periodic LCP (Nt = 256) solves the 2,000-element rod as
/// it solves the 20-element one. Measured: LCP-SSN ends max-iterations (400 over the mesh
/// sequence, residual 1.87, tip min -0.807, penetration 0.267); Lemke ends at its pivot
/// limit (12,900); the symmetric part of A has smallest eigenvalue -7.4e-3.
#[test]
#[ignore = "reason: on 2000 elements (Nt = 256) LCP-SSN ends max-iterations (residual 1.87) and Lemke at the pivot limit (12900); SSN-HB converges (tip min -0.52378)"]
fn two_thousand_elements_lcp_converges() {
    let spec = two_thousand_element_rod();
    let e = run("2000 elements", &spec, &hb(20), Method::SsnHb);
    let l = run("2000 elements", &spec, &hb(20), Method::LcpSsn);
    let e = e.converged().expect("SSN-HB converges");
    let l = l.converged().expect("LCP-SSN converges on 2000 elements");
    let tol = hb_penetration_bound(e)
        + 2.0 * std::f64::consts::PI * 0.5 * (e.stats.max - e.stats.min) / 256.0;
    assert!(
        (e.stats.min - l.stats.min).abs() <= tol,
        "SSN-HB {} vs LCP-SSN {}",
        e.stats.min,
        l.stats.min
    );
}

/// SSN-HB converges on 2,000 elements with its default settings (mesh-independent default
/// `c`, 10 times the static contact stiffness `1 / (G K^-1 G^T)`).
#[test]
fn two_thousand_elements_converge_with_default_settings() {
    let out = run(
        "2000 elements",
        &two_thousand_element_rod(),
        &hb(20),
        Method::SsnHb,
    );
    assert!(out.converged().is_some(), "{}", out.summary());
}

/// What the library should do: penalty HB converges on a refined rod with its default
/// settings, as SSN-HB does. Measured (modified mass, gap 0.5, omega_1, H = 20, default
/// penalty 1e5 K[tip, tip]): 100 elements converge in 33 iterations; 200 elements end
/// line-search-failed after 918 iterations (residual 1.46e-3, tip at +-0.5); 500, 1000 and
/// 2000 elements likewise (763, 603, 486 iterations), whatever k_p in 1e6..2e8. The penalty
/// homotopy starts from `K[tip, tip] = EA / h`, which grows with the mesh (as the old default
/// c did).
#[test]
fn penalty_hb_converges_on_200_elements() {
    let spec = RodSpec {
        elements: 200,
        contacts: vec![RodContact {
            node: 200,
            gap: 0.5,
        }],
        ..canonical()
    };
    let out = run("200 elements", &spec, &hb(20), Method::PenaltyHb);
    assert!(out.converged().is_some(), "penalty-hb: {}", out.summary());
}

#[test]
fn stiff_penalty_kp_1e8() {
    let mut s = hb(20);
    s.penalty_stiffness = Some(1e8);
    let out = run_all(
        "k_p = 1e8",
        &canonical(),
        &s,
        &[Method::PenaltyHb, Method::SsnHb],
    );
    // A stiff penalty tends to exact contact: its tip minimum approaches SSN-HB's within the
    // penalty penetration max|λ|/k_p plus the HB truncation bound.
    if let (Some(p), Some(e)) = (out[0].converged(), out[1].converged()) {
        let tol = hb_penetration_bound(e) + 1e-6;
        assert!(
            (p.stats.min - e.stats.min).abs() <= tol,
            "penalty {} vs SSN-HB {}",
            p.stats.min,
            e.stats.min
        );
    }
}

/// The `c` SSN-HB uses on the canonical rod when the scene leaves it out.
fn default_c() -> f64 {
    let rod = build_rod(&canonical()).unwrap();
    SsnHb::new(&rod.model, &HbOptions::default()).unwrap().c()
}

#[test]
fn complementarity_constant_across_six_decades() {
    let c0 = default_c();
    let mut converged = Vec::new();
    for e in -3..=3 {
        let factor = 10f64.powi(e);
        let mut s = hb(20);
        s.c = Some(c0 * factor);
        let case = format!("c = 1e{e} x default");
        if let Outcome::Converged(sol) = run(&case, &canonical(), &s, Method::SsnHb) {
            converged.push((factor, sol));
        }
    }
    // The Galerkin projection of the complementarity function vanishes, not the function at
    // every sample, so the zeros move with c -- within the HB truncation error (measured:
    // tip minima within 6e-4 of each other, bound 1.4e-2).
    let (_, reference) = converged
        .iter()
        .find(|(f, _)| *f == 1.0)
        .expect("the default c must converge");
    let tol = hb_penetration_bound(reference);
    for (f, s) in &converged {
        assert!(
            (s.stats.min - reference.stats.min).abs() <= tol,
            "c factor {f}: tip min {} vs {} (tol {tol:e})",
            s.stats.min,
            reference.stats.min
        );
    }
    // Measured: every factor up to 1e2 converges (default c = 10 EA/L = 10 here).
    for f in [1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0] {
        assert!(
            converged.iter().any(|(g, _)| *g == f),
            "c factor {f} did not converge"
        );
    }
}

/// What the library should do: converge for large `c` too within the scene's 200
/// iterations (the default c is 10 EA/L = 10 on the canonical rod; measured: c = 2000
/// converges after 300 iterations).
#[test]
#[ignore = "reason: SSN-HB with c = 1e3 x default (c = 1e4) stops at max-iterations (200, best residual 4.51e-3, tip min -0.49998: stuck near the start)"]
fn large_complementarity_constant_converges() {
    let mut s = hb(20);
    s.c = Some(1e3 * default_c());
    let out = run("c = 1e3 x default", &canonical(), &s, Method::SsnHb);
    assert!(out.converged().is_some(), "c factor 1e3: {}", out.summary());
}

#[test]
fn superharmonic_resonance_half_omega_1() {
    let spec = RodSpec {
        frequency: FrequencySpec::Ratio(0.5),
        contacts: vec![RodContact {
            node: 20,
            gap: 0.02,
        }],
        ..canonical()
    };
    let out = run_all("omega_1/2, gap 0.02", &spec, &hb(20), &ALL);
    cross_check("omega_1/2, gap 0.02", &out, &ALL);
}

fn third_omega_1() -> RodSpec {
    RodSpec {
        frequency: FrequencySpec::Ratio(1.0 / 3.0),
        contacts: vec![RodContact {
            node: 20,
            gap: 0.01,
        }],
        ..canonical()
    }
}

#[test]
fn superharmonic_resonance_third_omega_1() {
    let out = run_all("omega_1/3, gap 0.01", &third_omega_1(), &hb(20), &ALL);
    cross_check("omega_1/3, gap 0.01", &out, &ALL);
    // SSN-HB converges since the hybrid globalization restarts from the initial guess after
    // its full-step phase (before: line-search-failed after 79 iterations).
    assert!(out[0].converged().is_some(), "SSN-HB: {}", out[0].summary());
    // Lemke and penalty HB converge here (measured); they agree within the HB bound.
    let p = out[1]
        .converged()
        .expect("penalty HB converges at omega_1/3");
    let l = out[2].converged().expect("Lemke converges at omega_1/3");
    let tol = hb_penetration_bound(p) + 1e-3;
    assert!(
        (p.stats.min - l.stats.min).abs() <= tol,
        "penalty {} vs Lemke {}",
        p.stats.min,
        l.stats.min
    );
}

/// What the library should do: the semismooth LCP solves the superharmonic case that
/// Lemke solves (same LCP).
#[test]
#[ignore = "reason: at omega_1/3, gap 0.01, LCP-SSN (Nt = 256) ends line-search-failed after 368 iterations (residual 1.3e-2, tip min -0.02291), while Lemke solves the same LCP (269 pivots, tip min -0.028124)"]
fn superharmonic_third_converges_with_lcp_ssn() {
    let out = run(
        "omega_1/3, gap 0.01",
        &third_omega_1(),
        &hb(20),
        Method::LcpSsn,
    );
    assert!(out.converged().is_some(), "lcp-ssn: {}", out.summary());
}

#[test]
fn two_contact_nodes_scene() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/scenes/two_contacts.toml");
    let scene = Scene::from_path(&path).unwrap();
    let out = run_all("two contacts (scene)", &scene.rod, &scene.solver, &ALL);
    cross_check("two contacts (scene)", &out, &ALL);
}

/// Continuation from `0.5 ω_1` (no contact: the linear response is far below the gap) up
/// through the resonance: the branch touches the obstacle (grazing) and continues with
/// contact. Checks: the sweep ends cleanly, reaches the end or says why not, every point is
/// finite, no point penetrates beyond the truncation bound, contact does appear.
#[test]
fn continuation_crosses_the_grazing_point() {
    let rod = build_rod(&canonical()).unwrap();
    let gap = 0.5;
    for method in [Method::SsnHb, Method::PenaltyHb] {
        let mut settings = with_method(method, &hb(10));
        settings.max_iterations = 50;
        let sweep = SweepSettings::new(0.5, 1.5);
        let run = catch_unwind(AssertUnwindSafe(|| {
            frequency_response(&rod, &settings, &sweep, None)
        }));
        let curve = match run {
            Err(_) => panic!("continuation / {}: panicked", method.name()),
            Ok(Err(e)) => {
                println!(
                    "HARD | {:<34} | {:<10} | error: {e}",
                    "continuation 0.5 -> 1.5",
                    method.name()
                );
                continue;
            }
            Ok(Ok(c)) => c,
        };
        let ratios = curve.omega_ratio();
        let touching = curve.tip_max.iter().filter(|&&m| m >= gap - 1e-3).count();
        let worst = curve
            .tip_max
            .iter()
            .fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        println!(
            "HARD | {:<34} | {:<10} | {:<28} | {:>5} | points {} | last ratio {:.4} | touching {} | max tip {:.6}",
            "continuation 0.5 -> 1.5",
            method.name(),
            if curve.converged { "converged".to_string() } else { format!("NOT: {}", curve.termination) },
            curve.initial_iterations,
            curve.points(),
            ratios.last().copied().unwrap_or(f64::NAN),
            touching,
            worst,
        );
        assert!(
            curve.points() >= 2,
            "{}: {} points",
            method.name(),
            curve.points()
        );
        for v in curve
            .tip_max
            .iter()
            .chain(&curve.tip_min)
            .chain(&curve.omega)
        {
            assert!(
                v.is_finite(),
                "{}: non-finite point on the branch",
                method.name()
            );
        }
        assert!(
            curve.tip_max[0] < gap - 0.1,
            "{}: starts in contact: {}",
            method.name(),
            curve.tip_max[0]
        );
        if !curve.converged {
            assert!(!curve.termination.is_empty());
        }
        // Twice the HB truncation bound for a half amplitude of at most ~1 (module docs),
        // plus the penalty's own penetration.
        let bound = 2.0 * 2.0 * 1.0 / (std::f64::consts::PI * 10.0);
        assert!(
            worst <= gap + bound,
            "{}: tip max {worst} beyond gap + {bound}",
            method.name()
        );
        assert!(
            touching > 0,
            "{}: the branch never reaches the obstacle",
            method.name()
        );
    }
}
