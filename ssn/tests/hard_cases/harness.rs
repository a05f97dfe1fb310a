//! The hard cases' harness: the rods and settings of the cases, every method run on a
//! case with its documented outcome asserted, the plausibility checks and the comparisons
//! of converged answers (bounds and margins in the module docs of `hard_cases.rs`).

use crate::common;

use semismooth::newton;
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};
use semismooth_contact::solve::{solve, Solution, Termination};
use ssn::scene::{Method, SolverSettings};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The canonical rod (paper Fig. 1) with the modified mass.
pub(crate) fn canonical() -> RodSpec {
    common::canonical(MassModel::Modified)
}

/// The canonical modified-mass rod with its tip contact at `gap`.
pub(crate) fn with_gap(gap: f64) -> RodSpec {
    common::refined(20, gap)
}

/// SSN-HB settings with `H` harmonics (scene defaults, 200 iterations at most).
pub(crate) fn hb(h: usize) -> SolverSettings {
    SolverSettings::with_harmonics(h)
}

pub(crate) fn with_method(method: Method, base: &SolverSettings) -> SolverSettings {
    let mut s = base.clone();
    s.method = method;
    if !method.is_harmonic_balance() {
        s.time_samples = 256;
    }
    s
}

pub(crate) const ALL: [Method; 4] = [
    Method::SsnHb,
    Method::PenaltyHb,
    Method::LcpLemke,
    Method::LcpSsn,
];
pub(crate) const HB_ONLY: [Method; 2] = [Method::SsnHb, Method::PenaltyHb];

/// Twice the truncation bound `2 A / (π H)` of a tip with a velocity jump (module docs).
pub(crate) fn hb_penetration_bound(s: &Solution) -> f64 {
    let h = s.harmonics.expect("HB solution") as f64;
    let half_amplitude = 0.5 * (s.stats.max - s.stats.min);
    2.0 * 2.0 * half_amplitude / (std::f64::consts::PI * h)
}

/// Outcome of one (case, method) run.
#[derive(Debug)]
pub(crate) enum Outcome {
    Converged(Solution),
    NotConverged(Solution),
    Error(String),
}

impl Outcome {
    /// One line: the termination and numbers, or the error (not the whole solution).
    pub(crate) fn summary(&self) -> String {
        match self {
            Outcome::Converged(s) | Outcome::NotConverged(s) => format!(
                "{} after {} iterations, residual {:e}, tip min {}",
                s.termination, s.iterations, s.residual_norm, s.stats.min
            ),
            Outcome::Error(e) => format!("error: {e}"),
        }
    }

    pub(crate) fn converged(&self) -> Option<&Solution> {
        match self {
            Outcome::Converged(s) => Some(s),
            _ => None,
        }
    }
}

/// The documented outcome of one method on one case.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Expect {
    /// Converges (then checked by [`assert_plausible`] and compared by [`cross_check`]).
    Converges,
    /// Ends without converging: the termination starts with `termination`, after a number
    /// of iterations (pivots for Lemke) in `iterations` (the measured count with a margin).
    Fails {
        termination: &'static str,
        iterations: (usize, usize),
    },
}

/// Asserts the documented outcome of every method (`expected[i]` belongs to `methods[i]`).
pub(crate) fn assert_outcomes(
    case: &str,
    outcomes: &[Outcome],
    methods: &[Method],
    expected: &[Expect],
) {
    for ((method, outcome), expect) in methods.iter().zip(outcomes).zip(expected) {
        let what = format!("{case} / {}", method.name());
        match (expect, outcome) {
            (Expect::Converges, Outcome::Converged(_)) => {}
            (Expect::Converges, other) => {
                panic!("{what} must converge: {}", other.summary())
            }
            (
                Expect::Fails {
                    termination,
                    iterations: (lo, hi),
                },
                Outcome::NotConverged(s),
            ) => {
                assert!(
                    s.termination.to_string().starts_with(termination),
                    "{what}: expected {termination}, got {}",
                    s.termination
                );
                assert!(
                    (*lo..=*hi).contains(&s.iterations),
                    "{what}: {termination} after {} iterations, measured window [{lo}, {hi}]",
                    s.iterations
                );
            }
            (Expect::Fails { termination, .. }, other) => panic!(
                "{what}: documented as ending {termination}, got {} (if it now converges, \
                 make it `Expect::Converges` and compare it)",
                other.summary()
            ),
        }
    }
}

/// Runs every method of the case, asserts the documented outcomes and compares the converged
/// answers with each other ([`cross_check`], against the differences `measured` on it).
pub(crate) fn check_case(
    case: &str,
    spec: &RodSpec,
    base: &SolverSettings,
    expected: &[(Method, Expect)],
    measured: Measured,
) -> Vec<Outcome> {
    let methods: Vec<Method> = expected.iter().map(|(m, _)| *m).collect();
    let expect: Vec<Expect> = expected.iter().map(|(_, e)| *e).collect();
    let out = run_all(case, spec, base, &methods);
    assert_outcomes(case, &out, &methods, &expect);
    cross_check(case, &out, &methods, measured);
    out
}

/// The tip-minimum differences measured on a case (release build), per pair of methods that
/// converge on it: SSN-HB vs Lemke, SSN-HB vs penalty HB, Lemke vs LCP-SSN. `NaN` where a
/// method of the pair does not converge (then the pair is not compared).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Measured {
    hb_lemke: f64,
    hb_penalty: f64,
    lemke_ssn: f64,
}

impl Measured {
    /// A case where every method converges.
    pub(crate) fn all(hb_lemke: f64, hb_penalty: f64, lemke_ssn: f64) -> Self {
        Self {
            hb_lemke,
            hb_penalty,
            lemke_ssn,
        }
    }

    /// A case where only SSN-HB and penalty HB converge (or run).
    pub(crate) fn hb_only(hb_penalty: f64) -> Self {
        Self::all(f64::NAN, hb_penalty, f64::NAN)
    }

    /// A case where no two methods that [`cross_check`] compares both converge.
    pub(crate) fn none() -> Self {
        Self::all(f64::NAN, f64::NAN, f64::NAN)
    }
}

/// `method` ends with `termination` after a number of iterations in `iterations`.
pub(crate) fn fails(
    method: Method,
    termination: &'static str,
    iterations: (usize, usize),
) -> (Method, Expect) {
    (
        method,
        Expect::Fails {
            termination,
            iterations,
        },
    )
}

/// Every method of `methods` converges.
pub(crate) fn all_converge(methods: &[Method]) -> Vec<(Method, Expect)> {
    methods.iter().map(|&m| (m, Expect::Converges)).collect()
}

/// How much a measured difference may grow before a comparison fails. The differences are
/// deterministic (the same bits on every run); what legitimately moves them is a change of
/// path to the same solution (another globalization, reordered sums), which moves the
/// answers by the solvers' tolerances, far below the differences. A change of an answer by
/// more than 4 times the measured difference is a regression.
pub(crate) const MARGIN: f64 = 5.0;

/// Differences at round-off (the same LCP solved by two solvers) are measured from 1e-17 to
/// 2e-14; below this floor a difference is not a measurement but rounding, which other
/// FFT kernels (SIMD widths) can change.
pub(crate) const ROUND_OFF: f64 = 1e-13;

/// The tip minima of `a` and `b` differ by at most `MARGIN * max(measured, ROUND_OFF)`
/// and by at most the a-priori `bound` of the comparison (truncation, discretisation or
/// solver tolerance; `what` names the comparison, printed as a table line). The a-priori
/// bounds hold for any impact and are 10 to 1000 times what these gentle cases measure, so
/// alone they would let a regression through.
pub(crate) fn assert_tip_min_close(
    what: &str,
    a: &Solution,
    b: &Solution,
    bound: f64,
    measured: f64,
) {
    let tol = bound.min(MARGIN * measured.max(ROUND_OFF));
    let diff = (a.stats.min - b.stats.min).abs();
    println!("HARD | {what} | tip min diff {diff:.2e} (tol {tol:.2e})");
    assert!(
        diff <= tol,
        "{what}: tip min {} vs {} (diff {diff:e} > {tol:e})",
        a.stats.min,
        b.stats.min
    );
}

/// How far SSN-HB and an LCP with `nt` steps per period may differ on the tip minimum (away
/// from the contact, where the response is smooth): the HB truncation bound plus the LCP's
/// first-order time discretisation, `ω A Δt = 2 π A / Nt` with `Δt = T / Nt` (one step of
/// motion at the amplitude `A`).
pub(crate) fn hb_vs_lcp_tolerance(hb: &Solution, nt: usize) -> f64 {
    let a = 0.5 * (hb.stats.max - hb.stats.min);
    hb_vs_lcp_bound(a, hb.harmonics.expect("HB solution"), nt)
}

/// [`hb_vs_lcp_tolerance`] for a half amplitude `a`, `h` harmonics and `nt` steps:
/// `4 a / (π h) + 2 π a / nt`.
pub(crate) fn hb_vs_lcp_bound(a: f64, h: usize, nt: usize) -> f64 {
    let pi = std::f64::consts::PI;
    2.0 * 2.0 * a / (pi * h as f64) + 2.0 * pi * a / nt as f64
}

pub(crate) fn print_row(case: &str, method: Method, outcome: &Outcome) {
    match outcome {
        Outcome::Converged(s) | Outcome::NotConverged(s) => println!(
            "HARD | {case:<34} | {:<10} | {:<28} | {:>5} | {:>9.2e} | {:>10.6} | {:>9.2e}",
            method.name(),
            if s.converged() {
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
pub(crate) fn assert_finite(case: &str, method: Method, s: &Solution) {
    let what = format!("{case} / {}", method.name());
    assert!(
        s.observed.iter().all(|v| v.is_finite()),
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
    if s.converged() {
        assert!(
            s.residual_norm.is_finite(),
            "{what}: residual {}",
            s.residual_norm
        );
    } else {
        assert!(
            !ssn::words::termination(&s.termination).is_empty(),
            "{what}: no termination reason"
        );
        assert!(
            s.residual_norm.is_finite()
                || s.termination == Termination::Newton(newton::Termination::NonFinite),
            "{what}: residual {} with termination {}",
            s.residual_norm,
            s.termination
        );
    }
}

/// Physical plausibility of a converged answer (module docs).
pub(crate) fn assert_plausible(
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
        .map(|f| common::max_abs(f))
        .fold(0.0, f64::max);
    let bound = match method {
        Method::SsnHb => hb_penetration_bound(s),
        Method::PenaltyHb => {
            let kp = settings.penalty_stiffness.unwrap_or(
                ssn::scene::DEFAULT_RELATIVE_PENALTY * rod.model.contact_stiffness_scale(),
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
pub(crate) fn solve_once(
    case: &str,
    rod: &RodModel,
    settings: &SolverSettings,
) -> Result<Solution, String> {
    let run = catch_unwind(AssertUnwindSafe(|| solve(rod, rod.omega(), settings, None)));
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
pub(crate) fn run(case: &str, spec: &RodSpec, base: &SolverSettings, method: Method) -> Outcome {
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
                bits(&s.observed),
                bits(&again.observed),
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
            let converged = s.converged();
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

pub(crate) fn run_all(
    case: &str,
    spec: &RodSpec,
    base: &SolverSettings,
    methods: &[Method],
) -> Vec<Outcome> {
    methods.iter().map(|&m| run(case, spec, base, m)).collect()
}

/// When two methods both converged, their tip minima agree: SSN-HB and Lemke within
/// [`hb_vs_lcp_tolerance`], SSN-HB and penalty HB within both truncation bounds plus the
/// penalty's penetration, Lemke and LCP-SSN (the same LCP) to the solvers' tolerance.
///
/// Each pair that converged must have its difference in `measured`.
pub(crate) fn cross_check(
    case: &str,
    outcomes: &[Outcome],
    methods: &[Method],
    measured: Measured,
) {
    let find = |m: Method| {
        methods
            .iter()
            .position(|&x| x == m)
            .and_then(|i| outcomes[i].converged())
    };
    let known = |what: &str, m: f64| {
        assert!(
            !m.is_nan(),
            "{case}: {what} converged: state its measured difference"
        );
        m
    };
    if let (Some(hb), Some(lcp)) = (find(Method::SsnHb), find(Method::LcpLemke)) {
        // Plus 1e-9 for the solvers' tolerances (the bound vanishes for a tip at rest).
        let tol = hb_vs_lcp_tolerance(hb, lcp.time_samples) + 1e-9;
        let m = known("ssn-hb vs lcp-lemke", measured.hb_lemke);
        assert_tip_min_close(
            &format!("{case:<34} | ssn-hb vs lcp-lemke"),
            hb,
            lcp,
            tol,
            m,
        );
    }
    if let (Some(e), Some(p)) = (find(Method::SsnHb), find(Method::PenaltyHb)) {
        // Same harmonics and quadrature; both within the truncation bound of the exact
        // periodic answer, the penalty also within its own penetration max|λ| / k_p.
        let tol = hb_penetration_bound(e) + hb_penetration_bound(p) + p.stats.max_penetration;
        let m = known("ssn-hb vs penalty-hb", measured.hb_penalty);
        assert_tip_min_close(&format!("{case:<34} | ssn-hb vs penalty-hb"), e, p, tol, m);
    }
    if let (Some(a), Some(b)) = (find(Method::LcpLemke), find(Method::LcpSsn)) {
        // Same LCP, two solvers: the solution of a P-matrix LCP is unique; 1e-8 of the
        // amplitude covers the Newton tolerance 1e-10 on the forces times the compliance.
        let tol = 1e-8 * (1.0 + a.stats.min.abs());
        let m = known("lcp-lemke vs lcp-ssn", measured.lemke_ssn);
        assert_tip_min_close(&format!("{case:<34} | lcp-lemke vs lcp-ssn"), a, b, tol, m);
    }
}

/// Runs `method` on the case (as [`run`]) and returns the solution; fails unless it
/// converged.
pub(crate) fn run_converged(
    case: &str,
    spec: &RodSpec,
    base: &SolverSettings,
    method: Method,
) -> Solution {
    match run(case, spec, base, method) {
        Outcome::Converged(s) => s,
        other => panic!(
            "{case} / {} must converge: {}",
            method.name(),
            other.summary()
        ),
    }
}
