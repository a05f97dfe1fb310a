//! The harmonic operator and the general load: SSN-HB (dense, structured, condensed) and
//! penalty HB against a direct dense complex solve per harmonic, loads on several harmonics
//! with sine parts and a travelling wave, the modal damping `xi` as a second parameter of
//! the operator, and the factorization cache keyed on it.

mod common;

use common::dense_kmd;
use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{Complex, DMatrix, DVector};
use semismooth::linalg::FaerDenseLu;
use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, Residual};
use semismooth_contact::hb::{
    CondensedSsnHb, HbJacobian, HbOptions, PenaltyHb, PenaltyHbOptions, SsnHb, StructuredHbSolver,
};
use semismooth_contact::model::{ContactPoint, HarmonicLoad, StructuralModel};
use semismooth_contact::operator::OperatorParameter;

const N: usize = 4;
const H: usize = 3;
const OMEGA: f64 = 1.3;

/// A damped 4-dof chain (`D = 0.05 K + 0.01 M`) with a contact on dof 3 whose gap (1e3) is
/// never closed by the loads below (responses of order 1), under `load`.
fn chain(load: HarmonicLoad) -> StructuralModel {
    let (mut kt, mut mt) = (Vec::new(), Vec::new());
    for i in 0..N {
        kt.push(Triplet::new(i, i, 2.0 + 0.3 * i as f64));
        if i + 1 < N {
            kt.push(Triplet::new(i, i + 1, -1.0));
            kt.push(Triplet::new(i + 1, i, -1.0));
        }
        mt.push(Triplet::new(i, i, 1.0 - 0.1 * i as f64));
    }
    let stiffness = SparseColMat::try_new_from_triplets(N, N, &kt).unwrap();
    let mass = SparseColMat::try_new_from_triplets(N, N, &mt).unwrap();
    StructuralModel::new(mass, stiffness, vec![0.0; N])
        .with_rayleigh_damping(0.01, 0.05)
        .with_contact(ContactPoint::new(N - 1, 1e3))
        .with_load(load)
}

/// A constant load, a travelling wave on harmonic 1 (a phase per dof) and a load with
/// cosine and sine parts on harmonic 2.
fn general_load() -> HarmonicLoad {
    let amplitude = [0.4, 0.3, 0.2, 0.5];
    let phase = [0.0, 0.9, 1.8, 2.7];
    let mut load = HarmonicLoad::travelling_wave(&amplitude, &phase).unwrap();
    load.add_harmonic(0, &[0.1, 0.0, -0.2, 0.05], &[0.0; N])
        .unwrap();
    load.add_harmonic(2, &[0.0, 0.3, 0.0, -0.1], &[0.25, 0.0, 0.15, 0.2])
        .unwrap();
    load
}

/// The exact harmonic-major coefficients `U` of the linear response (`N (2H + 1)`): per
/// harmonic the dense complex solve of `(K - (k w)^2 M + i k w (D - xi M)) z = c - i s`
/// (nalgebra's LU, independent of the code under test), `u_ck = Re z`, `u_sk = -Im z`.
fn exact_response(model: &StructuralModel, xi: f64) -> Vec<f64> {
    let (k, m, d) = dense_kmd(model);
    let mut u = vec![0.0; N * (2 * H + 1)];
    for h in 0..=H {
        let kw = h as f64 * OMEGA;
        let z_k = DMatrix::from_fn(N, N, |i, j| {
            Complex::new(
                k[(i, j)] - kw * kw * m[(i, j)],
                kw * (d[(i, j)] - xi * m[(i, j)]),
            )
        });
        let (cosine, sine) = model
            .load
            .harmonic(h)
            .map_or((vec![0.0; N], vec![0.0; N]), |(c, s)| {
                (c.to_vec(), s.to_vec())
            });
        let f = DVector::from_fn(N, |i, _| Complex::new(cosine[i], -sine[i]));
        let z = z_k.lu().solve(&f).expect("a regular damped block");
        for i in 0..N {
            if h == 0 {
                u[i] = z[i].re;
            } else {
                u[(2 * h - 1) * N + i] = z[i].re;
                u[2 * h * N + i] = -z[i].im;
            }
        }
    }
    u
}

/// `max |a - b| / max |b|`.
fn relative_gap(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let gap = a
        .iter()
        .zip(b)
        .fold(0.0f64, |s, (x, y)| s.max((x - y).abs()));
    gap / scale
}

/// One Newton step from zero: the solution of a problem that is linear near it (the contact
/// stays open, so its force is zero and the law's Jacobian is the identity).
fn newton_step<P, S>(problem: &mut P, solver: &mut S) -> Vec<f64>
where
    P: Residual + GeneralizedJacobian,
    S: Factorize<P::Jacobian> + LinearSolve,
{
    let mut x = vec![0.0; problem.dim()];
    let mut r = vec![0.0; problem.dim()];
    problem.residual(&x, &mut r).unwrap();
    let mut jac = problem.new_jacobian();
    problem.jacobian(&x, &mut jac).unwrap();
    solver.factor(&jac).unwrap();
    solver.solve_in_place(&mut r).unwrap();
    for (xi, ri) in x.iter_mut().zip(&r) {
        *xi = -ri;
    }
    x
}

fn options() -> HbOptions {
    HbOptions {
        harmonics: H,
        ..HbOptions::default()
    }
}

// Tolerance 1e-12 relative: every block is well conditioned (damped, away from resonance:
// condition numbers below 1e2), and both sides are LU solves with partial pivoting, so
// they agree to a few hundred roundings; a sign or harmonic error would be of order 1.
const TOLERANCE: f64 = 1e-12;

#[test]
fn loads_on_harmonic_two_with_sine_parts_and_travelling_waves_give_the_exact_linear_response() {
    let model = chain(general_load());
    let exact = exact_response(&model, 0.0);
    let len = N * (2 * H + 1);
    // Full SSN-HB, dense and structured linear solves.
    let mut hb = SsnHb::new(&model, OMEGA, &options()).unwrap();
    let dense = newton_step(&mut hb, &mut FaerDenseLu::new());
    assert!(relative_gap(&dense[..len], &exact) < TOLERANCE);
    let structured = newton_step(&mut hb, &mut StructuredHbSolver::new());
    assert!(relative_gap(&structured[..len], &exact) < TOLERANCE);
    // The contact stayed open: its force is zero, and the residual vanishes there.
    assert!(dense[len..].iter().all(|l| l.abs() < 1e-14));
    let mut r = vec![0.0; hb.dim()];
    hb.residual(&structured, &mut r).unwrap();
    assert!(r.iter().all(|v| v.abs() < 1e-13), "{r:?}");
    // Condensed SSN-HB: zero contact forces are its root, expanded to the response.
    let mut condensed = CondensedSsnHb::new(&model, OMEGA, &options()).unwrap();
    let zero = vec![0.0; condensed.dim()];
    let mut rc = vec![0.0; condensed.dim()];
    condensed.residual(&zero, &mut rc).unwrap();
    assert!(rc.iter().all(|v| *v == 0.0));
    let expanded = condensed.expand(&zero).unwrap();
    assert!(relative_gap(&expanded[..len], &exact) < TOLERANCE);
    // Penalty HB (its contact never penetrates, so its penalty force is zero).
    let penalty_options = PenaltyHbOptions {
        harmonics: H,
        time_samples: None,
        penalty_stiffness: 1e3,
    };
    let mut penalty = PenaltyHb::new(&model, OMEGA, &penalty_options).unwrap();
    let u = newton_step(&mut penalty, &mut StructuredHbSolver::new());
    assert!(relative_gap(&u, &exact) < TOLERANCE);
}

#[test]
fn modal_damping_enters_as_minus_xi_m_in_the_damping() {
    let model = chain(general_load());
    let xi = 0.07;
    let exact = exact_response(&model, xi);
    let len = N * (2 * H + 1);
    let mut hb = SsnHb::new(&model, OMEGA, &options()).unwrap();
    hb.set_modal_damping(xi).unwrap();
    for u in [
        newton_step(&mut hb, &mut FaerDenseLu::new()),
        newton_step(&mut hb, &mut StructuredHbSolver::new()),
    ] {
        assert!(relative_gap(&u[..len], &exact) < TOLERANCE);
    }
    let mut condensed = CondensedSsnHb::new(&model, OMEGA, &options()).unwrap();
    condensed.set_modal_damping(xi).unwrap();
    let expanded = condensed.expand(&vec![0.0; condensed.dim()]).unwrap();
    assert!(relative_gap(&expanded[..len], &exact) < TOLERANCE);
    assert!(hb.set_modal_damping(f64::NAN).is_err());
}

#[test]
fn residual_operator_derivatives_are_the_central_differences_of_the_residual() {
    let model = chain(general_load());
    let mut hb = SsnHb::new(&model, OMEGA, &options()).unwrap();
    hb.set_modal_damping(0.04).unwrap();
    let x: Vec<f64> = (0..hb.dim())
        .map(|i| ((i * 5) % 7) as f64 / 7.0 - 0.4)
        .collect();
    let step = 1e-4;
    for parameter in [OperatorParameter::Omega, OperatorParameter::ModalDamping] {
        let mut residual_at = |delta: f64| {
            match parameter {
                OperatorParameter::ModalDamping => hb.set_modal_damping(0.04 + delta).unwrap(),
                _ => hb.set_omega(OMEGA + delta).unwrap(),
            }
            let mut r = vec![0.0; hb.dim()];
            hb.residual(&x, &mut r).unwrap();
            r
        };
        let (plus, minus) = (residual_at(step), residual_at(-step));
        residual_at(0.0);
        let mut derivative = vec![0.0; hb.dim()];
        hb.residual_operator_derivative(parameter, &x, &mut derivative)
            .unwrap();
        // The residual is quadratic in w and linear in xi (the contact law does not depend
        // on them): the central difference is exact but for rounding, eps |R| / step.
        for (i, d) in derivative.iter().enumerate() {
            let fd = (plus[i] - minus[i]) / (2.0 * step);
            assert!((fd - d).abs() < 1e-9, "{parameter:?} {i}: {fd} vs {d}");
        }
    }
}

#[test]
fn changing_the_modal_damping_at_fixed_frequency_refactors_and_nothing_else_does() {
    let model = chain(general_load());
    let mut hb = SsnHb::new(&model, OMEGA, &options()).unwrap();
    let mut solver = StructuredHbSolver::new();
    let x = vec![0.0; hb.dim()];
    let mut jac: HbJacobian = hb.new_jacobian();
    let factor = |hb: &mut SsnHb, jac: &mut HbJacobian, solver: &mut StructuredHbSolver| {
        hb.jacobian(&x, jac).unwrap();
        solver.factor(jac).unwrap();
        solver.dynamic_factorizations()
    };
    assert_eq!(factor(&mut hb, &mut jac, &mut solver), 1);
    // Same w, same xi: the per-harmonic factorizations are reused.
    assert_eq!(factor(&mut hb, &mut jac, &mut solver), 1);
    hb.set_modal_damping(0.05).unwrap();
    assert_eq!(factor(&mut hb, &mut jac, &mut solver), 2);
    assert_eq!(factor(&mut hb, &mut jac, &mut solver), 2);
    hb.set_modal_damping(0.0).unwrap();
    assert_eq!(factor(&mut hb, &mut jac, &mut solver), 3);
    // The condensed problem refactors on a new xi, not on the same one.
    let mut condensed = CondensedSsnHb::new(&model, OMEGA, &options()).unwrap();
    assert_eq!(condensed.dynamic_factorizations(), 1);
    condensed.set_modal_damping(0.0).unwrap();
    assert_eq!(condensed.dynamic_factorizations(), 1);
    condensed.set_modal_damping(0.02).unwrap();
    assert_eq!(condensed.dynamic_factorizations(), 2);
}

#[test]
fn loads_beyond_the_harmonics_and_non_cosine_loads_of_the_lcp_are_refused() {
    let mut load = HarmonicLoad::cosine(vec![0.1; N]);
    load.add_harmonic(H + 1, &[0.0; N], &[1.0; N]).unwrap();
    let model = chain(load);
    assert!(SsnHb::new(&model, OMEGA, &options()).is_err());
    let model = chain(general_load());
    let lcp = semismooth_contact::lcp::PeriodicLcp::new(
        &model,
        OMEGA,
        semismooth_contact::lcp::PeriodicLcpOptions::default(),
    );
    assert!(matches!(
        lcp,
        Err(semismooth_contact::lcp::LcpError::Unsupported { .. })
    ));
}

/// `(u(t), u'(t))` of the harmonic-major coefficients `u` at frequency `OMEGA`.
fn evaluate(u: &[f64], t: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut v) = (u[..N].to_vec(), vec![0.0; N]);
    for k in 1..=H {
        let kw = k as f64 * OMEGA;
        let (s, c) = (kw * t).sin_cos();
        for i in 0..N {
            let (a, b) = (u[(2 * k - 1) * N + i], u[2 * k * N + i]);
            x[i] += a * c + b * s;
            v[i] += kw * (b * c - a * s);
        }
    }
    (x, v)
}

/// Largest gap over one period, relative to the largest displacement, between the march
/// with `steps` steps per period started on the exact periodic state and that state.
fn march_gap(model: &StructuralModel, exact: &[f64], steps: usize) -> f64 {
    use semismooth_contact::march::{MarchOptions, MarchScheme, MarchState, TimeMarcher};
    let (displacement, velocity) = evaluate(exact, 0.0);
    let start = MarchState {
        displacement,
        velocity,
        contact_force: vec![0.0],
    };
    let options = MarchOptions {
        steps_per_period: steps,
        scheme: MarchScheme::MOREAU_JEAN_DEFAULT,
        ..MarchOptions::default()
    };
    let mut march = TimeMarcher::new(model, OMEGA, &options, &start).unwrap();
    let (mut gap, mut scale) = (0.0f64, 0.0f64);
    for _ in 0..steps {
        march.step().unwrap();
        let (x, _) = evaluate(exact, march.time());
        for (a, b) in march.displacement().iter().zip(&x) {
            gap = gap.max((a - b).abs());
            scale = scale.max(b.abs());
        }
    }
    gap / scale
}

#[test]
fn time_marching_converges_at_second_order_to_the_exact_response_to_a_general_load() {
    let model = chain(general_load());
    let exact = exact_response(&model, 0.0);
    let (coarse, fine) = (
        march_gap(&model, &exact, 1000),
        march_gap(&model, &exact, 2000),
    );
    // Moreau-Jean with theta = 1/2 is the trapezoidal rule in free flight: halving the step
    // divides the error by 4 (measured 1.6e-5 and 4.0e-6, ratio 4.00; bounds with a margin
    // of 2.5 and 10 %); a load sampled at the wrong phase or harmonic would leave an error
    // of order 1.
    assert!(fine < 1e-5, "{fine}");
    assert!((3.6..4.4).contains(&(coarse / fine)), "{coarse} / {fine}");
}
