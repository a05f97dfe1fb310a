//! Nonlinear modes (EPMC on SSN-HB) against closed forms: the linear mode at small
//! amplitude, and the backbone of the bilinear oscillator (a stop through a spring, soft
//! and stiff).

mod common;

use common::sparse;
use faer::Mat;
use semismooth::continuation::ContinuationTermination;
use semismooth::linalg::DenseAssemble;
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::{solve, NewtonOptions, Tolerances};
use semismooth::polyalgorithm::{self, solve_smoothing, PolyalgorithmOptions};
use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent, Residual};
use semismooth_contact::describing_function::{jenkins_mode, terms_without_slider};
use semismooth_contact::hb::{HbOptions, SsnHb};
use semismooth_contact::model::{
    ContactPoint, ContactRow, FrictionPoint, HarmonicLoad, SparseMatrix, StructuralModel,
};
use semismooth_contact::modes::{
    backbone, AmplitudeMeasure, Backbone, BackboneOptions, BackbonePoint, Epmc, EpmcSolve,
    EpmcStructuredSolver, LinearMode, ModesError, MAX_DENSE_UNKNOWNS,
};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::structures::cantilever_with_tip_spring;

/// The chain `M = I`, `K = [[2, -1], [-1, 2]]` (natural frequencies 1 and sqrt 3, modes
/// (1, 1) and (1, -1)), proportional damping `D = alpha M + beta K`, a contact on dof 1
/// far beyond the amplitudes used.
fn damped_chain(alpha: f64, beta: f64) -> StructuralModel {
    let k = [(0, 0, 2.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 2.0)];
    let d: Vec<_> = k
        .iter()
        .map(|&(i, j, v)| (i, j, beta * v + if i == j { alpha } else { 0.0 }))
        .collect();
    let mass = sparse(2, &[(0, 0, 1.0), (1, 1, 1.0)]);
    StructuralModel::new(mass, sparse(2, &k), vec![0.0; 2])
        .with_damping(sparse(2, &d))
        .with_load(HarmonicLoad::zero(2))
        .with_contact(ContactPoint::new(1, 100.0))
}

#[test]
fn small_amplitude_gives_the_linear_frequency_and_damping_ratio_to_round_off() {
    let (alpha, beta) = (0.02, 0.01);
    let model = damped_chain(alpha, beta);
    let options = HbOptions {
        harmonics: 5,
        ..HbOptions::default()
    };
    for (mode, omega_n) in [(1, 1.0), (2, 3.0f64.sqrt())] {
        // zeta_r = alpha / (2 omega_r) + beta omega_r / 2 for D = alpha M + beta K.
        let zeta = alpha / (2.0 * omega_n) + beta * omega_n / 2.0;
        for measure in [AmplitudeMeasure::ModalCoordinate, AmplitudeMeasure::Dof(0)] {
            let mut epmc = Epmc::new(&model, &options, mode, measure).unwrap();
            let LinearMode {
                omega,
                damping_ratio,
                ..
            } = epmc.linear_mode().clone();
            assert!((omega - omega_n).abs() < 1e-14 * omega_n, "{omega}");
            assert!((damping_ratio - zeta).abs() < 1e-14, "{damping_ratio}");
            // Newton from a start 5 % off in w and half the damping.
            // Far below the gap 100: the problem is linear, any amplitude is small.
            epmc.set_parameter(1.0);
            let mut x = epmc.linear_start(1.0);
            let len = epmc.hb_len();
            x[len] *= 1.05;
            x[len + 1] *= 0.5;
            let newton = NewtonOptions {
                tolerances: Tolerances {
                    residual_floor: 1e-15,
                    ..Tolerances::absolute(1e-15)
                },
                ..NewtonOptions::default()
            };
            let report = solve(&mut epmc, &mut FaerDenseLu::new(), &mut x, &newton).unwrap();
            assert!(report.converged(), "{report:?}");
            // Round-off: a few ulps of the eigenvalues of 2 x 2 problems with O(1) entries.
            assert!(
                (epmc.omega(&x) - omega_n).abs() < 1e-13,
                "{}",
                epmc.omega(&x)
            );
            assert!(
                (epmc.damping_ratio(&x) - zeta).abs() < 1e-13,
                "{}",
                epmc.damping_ratio(&x)
            );
            let mut r = vec![0.0; epmc.dim()];
            epmc.residual(&x, &mut r).unwrap();
            assert!(r.iter().all(|v| v.abs() < 1e-12));
        }
    }
}

/// `m u'' + k u = -k_c (u - w)` with a massless node `w` behind the spring `k_c`, held by a
/// rigid stop at `w = gap`: the bilinear oscillator, stiffness `k` while `u < gap`, `k + k_c`
/// beyond (`m = k = 1`).
fn bilinear(gap: f64, k_c: f64) -> StructuralModel {
    StructuralModel {
        mass: sparse(2, &[(0, 0, 1.0)]),
        damping: None,
        stiffness: sparse(
            2,
            &[(0, 0, 1.0 + k_c), (0, 1, -k_c), (1, 0, -k_c), (1, 1, k_c)],
        ),
        load: HarmonicLoad::zero(2),
        contacts: vec![ContactPoint::new(1, gap)],
        friction: Vec::new(),
        cyclic: None,
        frictional_contacts: Vec::new(),
    }
}

/// The frequency of the free bilinear oscillator (`m = k = 1`, stiffness `1 + k_c` beyond
/// `gap > 0`) whose largest displacement is `a > gap`: the period is the time below the gap,
/// `(2 pi - 2 acos(gap / b)) / 1` on the ellipse of amplitude `b` about 0, plus the time
/// beyond, `2 acos((gap - e) / (a - e)) / w_2` on the ellipse about `e = k_c gap / (1 + k_c)`
/// with `w_2 = sqrt(1 + k_c)`; energy matches at `u = gap`:
/// `b^2 = gap^2 + w_2^2 ((a - e)^2 - (gap - e)^2)`.
fn bilinear_frequency(gap: f64, k_c: f64, a: f64) -> f64 {
    use std::f64::consts::PI;
    if a <= gap {
        return 1.0;
    }
    let w2 = (1.0 + k_c).sqrt();
    let e = k_c * gap / (1.0 + k_c);
    let b = (gap * gap + w2 * w2 * ((a - e).powi(2) - (gap - e).powi(2))).sqrt();
    let period = 2.0 * PI - 2.0 * (gap / b).acos() + 2.0 * ((gap - e) / (a - e)).acos() / w2;
    2.0 * PI / period
}

/// The largest error of the backbone's frequency against [`bilinear_frequency`] of its own
/// largest displacement, over the points in contact, with `harmonics` harmonics; asserts
/// the points are conservative (`xi` zero to round-off).
fn bilinear_backbone_error(gap: f64, k_c: f64, harmonics: usize) -> f64 {
    let model = bilinear(gap, k_c);
    let (branch, epmc) = common::mode_one_backbone(&model, 0.1, 2.0, harmonics);
    let mut error = 0.0f64;
    let mut in_contact = 0;
    for point in &branch.points {
        assert!(point.modal_damping.abs() < 1e-12, "{}", point.modal_damping);
        let u = &point.unknowns[..epmc.hb_len()];
        let samples = epmc.hb().displacement_samples(u, 0, 4096).unwrap();
        let largest = samples.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if largest > 1.05 * gap {
            in_contact += 1;
            error = error.max((point.omega - bilinear_frequency(gap, k_c, largest)).abs());
        } else if largest < gap {
            // Open all the time: the linear frequency, to round-off.
            assert!((point.omega - 1.0).abs() < 1e-13, "{}", point.omega);
        }
    }
    assert!(in_contact >= 5, "{in_contact}");
    error
}

#[test]
fn bilinear_backbone_converges_to_its_closed_form_with_the_harmonics() {
    // u'' has a kink where the contact opens and closes: u's coefficients fall like k^-4.
    // The largest frequency error over the backbone (near the onset of contact) was
    // measured at 1.9e-4, 3.2e-5, 5.1e-6 for H = 10, 20, 40 (a factor 6 per doubling,
    // order 2.6). Asserted: at least second order per doubling (factor 4), and the error
    // at H = 40 below 1e-5 of the frequency (about 1.1).
    let (gap, k_c) = (1.0, 3.0);
    let errors: Vec<f64> = [10, 20, 40]
        .iter()
        .map(|&h| bilinear_backbone_error(gap, k_c, h))
        .collect();
    assert!(errors[1] < errors[0] / 4.0, "{errors:?}");
    assert!(errors[2] < errors[1] / 4.0, "{errors:?}");
    assert!(errors[2] < 1e-5, "{errors:?}");
}

/// [`bilinear_frequency`] of the oscillator whose largest excursion away from the stop is
/// `b = -min u` (the amplitude of the ellipse about 0): `a - e = sqrt((b^2 - gap^2) / w_2^2 +
/// (gap - e)^2)` by the same energy match. With a stiff spring the largest displacement
/// barely passes `gap` and `w(a)` is too steep there to measure a backbone by; `w(b)` is not.
fn bilinear_frequency_by_excursion(gap: f64, k_c: f64, b: f64) -> f64 {
    if b <= gap {
        return 1.0;
    }
    let e = k_c * gap / (1.0 + k_c);
    let a = e + ((b * b - gap * gap) / (1.0 + k_c) + (gap - e).powi(2)).sqrt();
    bilinear_frequency(gap, k_c, a)
}

/// The largest error of the backbone's frequency against
/// [`bilinear_frequency_by_excursion`] of its own excursion, over the points in contact.
fn stiff_bilinear_backbone_error(gap: f64, k_c: f64, harmonics: usize) -> f64 {
    let model = bilinear(gap, k_c);
    let (branch, epmc) = common::mode_one_backbone(&model, 0.1, 2.0, harmonics);
    let mut error = 0.0f64;
    for point in &branch.points {
        let u = &point.unknowns[..epmc.hb_len()];
        let samples = epmc.hb().displacement_samples(u, 0, 4096).unwrap();
        let excursion = -samples.iter().copied().fold(f64::INFINITY, f64::min);
        if excursion > 1.05 * gap {
            let exact = bilinear_frequency_by_excursion(gap, k_c, excursion);
            error = error.max((point.omega - exact).abs());
        }
    }
    error
}

#[test]
fn stiff_bilinear_backbone_passes_the_onset_and_converges_with_the_harmonics() {
    // k_c = 3000: nearly the rigid stop's corner at the onset of contact (the backbone's
    // continuation passes it at every H), and rigid-like convergence until the harmonics
    // resolve the contact time pi / sqrt(1 + k_c) = 0.057 of the period 2 pi. Measured:
    // 7.0e-2, 3.3e-2, 1.1e-2, 2.3e-3 at H = 10, 20, 40, 80 (factors 2.1, 3.0, 4.8; the
    // largest error sits near the onset, so it moves with where the points fall).
    // Asserted: a factor 1.5 per doubling, and below 3e-3 at H = 80 (30 % above).
    let (gap, k_c) = (1.0, 3000.0);
    let errors: Vec<f64> = [10, 20, 40, 80]
        .iter()
        .map(|&h| stiff_bilinear_backbone_error(gap, k_c, h))
        .collect();
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0] / 1.5, "{errors:?}");
    }
    assert!(errors[3] < 3e-3, "{errors:?}");
}

/// The Jenkins oscillator: `m = k = 1`, light viscous damping `c` on the mass, a tangential
/// spring `k_t` from the mass to a massless slider (dof 1) held by Coulomb friction with the
/// slip limit `limit`, forced by `force cos(w t)` on the mass.
fn jenkins(c: f64, k_t: f64, limit: f64, force: f64) -> StructuralModel {
    StructuralModel {
        mass: sparse(2, &[(0, 0, 1.0)]),
        damping: Some(sparse(2, &[(0, 0, c)])),
        stiffness: sparse(
            2,
            &[(0, 0, 1.0 + k_t), (0, 1, -k_t), (1, 0, -k_t), (1, 1, k_t)],
        ),
        load: HarmonicLoad::cosine(vec![force, 0.0]),
        contacts: Vec::new(),
        // mu = 0.5 under a prescribed normal load 2 limit.
        friction: vec![FrictionPoint::prescribed(
            ContactRow::unit(1, 1.0),
            0.5,
            2.0 * limit,
        )],
        cyclic: None,
        frictional_contacts: Vec::new(),
    }
}

/// Harmonic-balance unknowns (`blocks` blocks of `2H + 1` coefficients of width
/// `widths[b]`) shifted in time by a quarter period: `u(t) -> u(t - T/4)`, harmonic `k`'s
/// `(a, b)` rotated by `k pi / 2`.
fn quarter_period_later(x: &[f64], harmonics: usize, widths: &[usize]) -> Vec<f64> {
    let mut out = x.to_vec();
    let mut start = 0;
    for &width in widths {
        for k in 1..=harmonics {
            let (sin, cos) = (k as f64 * std::f64::consts::FRAC_PI_2).sin_cos();
            for i in 0..width {
                let (ca, sb) = (start + (2 * k - 1) * width + i, start + 2 * k * width + i);
                out[ca] = x[ca] * cos - x[sb] * sin;
                out[sb] = x[ca] * sin + x[sb] * cos;
            }
        }
        start += (2 * harmonics + 1) * width;
    }
    out
}

/// `u^T A u` of a sparse symmetric `A`.
fn quadratic(a: &SparseMatrix, u: &[f64]) -> f64 {
    let a = a.as_ref();
    (0..a.ncols())
        .map(|j| {
            let column: f64 = (a.row_idx_of_col(j).zip(a.val_of_col(j)))
                .map(|(i, v)| v * u[i])
                .sum();
            column * u[j]
        })
        .sum()
}

/// A forced response's phase resonance at a dof and the modal damping of its energy
/// balance.
struct PhaseResonance {
    omega: f64,
    /// `|U_1|` of the dof (its sine part: the cosine part is zero).
    amplitude: f64,
    /// `xi = f . b_1 / (w sum_k k^2 |U_k|_M^2)`: the force's work per cycle, `pi f . b_1`,
    /// against `xi` times `integral u'^T M u' dt = pi w sum_k k^2 |U_k|_M^2`.
    modal_damping: f64,
    /// `sqrt(1 - |U_1|_M^2 / sum_k k^2 |U_k|_M^2)`: the share of the harmonics above the
    /// first in the velocity.
    higher: f64,
}

/// The phase resonance of `model`'s forced response at `dof` (the cosine part of its
/// harmonic 1 zero: it lags the cosine force by a quarter period), by the secant method in
/// `w` on SSN-HB solves from `x` at `w`.
fn phase_resonance(
    model: &StructuralModel,
    options: &HbOptions,
    dof: usize,
    mut w: f64,
    x: &mut Vec<f64>,
) -> PhaseResonance {
    let n = model.dofs();
    let (cos, sin) = (n + dof, 2 * n + dof);
    let mut hb = SsnHb::new(model, w, options).unwrap();
    let newton = PolyalgorithmOptions::default();
    let cosine_part = |hb: &mut SsnHb, w: f64, x: &mut Vec<f64>| {
        hb.set_omega(w).unwrap();
        let report = solve_smoothing(hb, &mut FaerDenseLu::new(), x, &newton).unwrap();
        assert!(report.converged(), "{report:?}");
        x[cos]
    };
    let (mut w_old, mut f_old) = (w * 1.001, cosine_part(&mut hb, w * 1.001, x));
    for _ in 0..30 {
        let f = cosine_part(&mut hb, w, x);
        // The solves' own tolerance leaves |F| ~ 1e-10 and the cosine part moves by
        // about that much: stop there.
        if f.abs() < 1e-9 * x[sin].abs() || f == f_old {
            break;
        }
        let next = w - f * (w - w_old) / (f - f_old);
        (w_old, f_old, w) = (w, f, next);
    }
    assert!(x[cos].abs() < 1e-9 * x[sin].abs(), "{} {}", x[cos], x[sin]);
    let block = |j: usize| &x[j * n..(j + 1) * n];
    let mass = |j: usize| quadratic(&model.mass, block(j));
    let motion: f64 = (1..=options.harmonics)
        .map(|k| (k * k) as f64 * (mass(2 * k - 1) + mass(2 * k)))
        .sum();
    let force: f64 = (model.load.forcing_cosine().iter().zip(block(2)))
        .map(|(f, b)| f * b)
        .sum();
    PhaseResonance {
        omega: w,
        amplitude: x[sin].abs(),
        modal_damping: force / (w * motion),
        higher: (1.0 - (mass(1) + mass(2)) / motion).max(0.0).sqrt(),
    }
}

/// The relative differences in `w` and `xi` between the phase resonance of `forced` at
/// `dof` and `branch` at that amplitude (Newton on `epmc` from the branch point whose
/// energy balance `xi w |U_c1|_M^2 = f . U_c1` fits `forced`'s load `f` best), and the
/// share of the higher harmonics; `widths` are the dofs and the contact rows.
fn backbone_against_forced(
    branch: &Backbone,
    epmc: &mut Epmc,
    forced: &StructuralModel,
    dof: usize,
    widths: &[usize],
) -> (f64, f64, f64) {
    let n = forced.dofs();
    let basis = epmc.hb().basis();
    let options = HbOptions {
        harmonics: basis.harmonics(),
        time_samples: Some(basis.time_samples()),
        c: Some(epmc.hb().c()),
    };
    let load = forced.load.forcing_cosine();
    let misfit = |p: &BackbonePoint| {
        let first = &p.unknowns[n..2 * n];
        let work: f64 = load.iter().zip(first).map(|(f, a)| f * a).sum();
        (p.modal_damping * p.omega * quadratic(&forced.mass, first) / work - 1.0).abs()
    };
    let start = (branch.points.iter())
        .min_by(|p, q| misfit(p).total_cmp(&misfit(q)))
        .unwrap();
    let len = epmc.hb_len();
    let mut x = quarter_period_later(&start.unknowns[..len], options.harmonics, widths);
    let resonance = phase_resonance(forced, &options, dof, start.omega, &mut x);
    // The backbone at that amplitude, exactly (Newton on EPMC from the point nearest in
    // amplitude).
    epmc.set_parameter(resonance.amplitude);
    let nearest = (branch.points.iter())
        .min_by(|p, q| {
            let d = |p: &BackbonePoint| (p.amplitude - resonance.amplitude).abs();
            d(p).total_cmp(&d(q))
        })
        .unwrap();
    let mut y = nearest.unknowns.clone();
    let newton = PolyalgorithmOptions::default();
    let report = polyalgorithm::solve(epmc, &mut FaerDenseLu::new(), &mut y, &newton).unwrap();
    assert!(report.converged(), "{report:?}");
    let (w, xi) = (resonance.omega, resonance.modal_damping);
    (
        ((w - epmc.omega(&y)) / w).abs(),
        ((xi - epmc.modal_damping(&y)) / xi).abs(),
        resonance.higher,
    )
}

#[test]
fn jenkins_backbone_carries_the_phase_resonances_of_the_forced_responses() {
    let (c, k_t, limit) = (0.01, 3.0, 0.5);
    let options = HbOptions {
        harmonics: 15,
        ..HbOptions::default()
    };
    let free = jenkins(c, k_t, limit, 0.0);
    let mut backbone_options = BackboneOptions::new(1, AmplitudeMeasure::Dof(0), 0.01, 3.0);
    backbone_options.hb = options;
    let branch = backbone(&free, &backbone_options).unwrap();
    assert!(matches!(
        branch.termination,
        ContinuationTermination::ReachedBound { .. }
    ));
    // Stuck at small amplitude: w = sqrt(1 + k_t), zeta = c / (2 w).
    let first = &branch.points[0];
    assert!((first.omega - 2.0).abs() < 1e-12 && (first.damping_ratio - c / 4.0).abs() < 1e-12);
    let mut epmc = Epmc::new(&free, &options, 1, AmplitudeMeasure::Dof(0)).unwrap();
    for force in [0.02, 0.1, 0.3, 0.6] {
        let forced = jenkins(c, k_t, limit, force);
        let (dw, dxi, higher) = backbone_against_forced(&branch, &mut epmc, &forced, 0, &[2, 1]);
        // The forced motion and the EPMC motion differ only through the harmonics above
        // the first (the force is harmonic 1, -xi M u' has every harmonic): relative
        // differences of the order of their share `higher` of the velocity (measured
        // 3e-3 to 4e-2). Measured differences: w 2e-6 to 6e-4, xi 7e-4 to 5e-3.
        assert!(dw < higher && dw < 1e-3, "F {force}: w {dw} {higher}");
        assert!(dxi < higher && dxi < 1e-2, "F {force}: xi {dxi} {higher}");
    }
}

#[test]
fn rod_backbone_carries_the_phase_resonances_of_the_forced_responses() {
    // The paper's rod with a massless contact node, its tip stop at 0.5, 1 % damping.
    let mut spec = RodSpec::canonical();
    spec.mass = MassModel::Modified;
    let rod = build_rod(&spec).unwrap();
    let (model, tip) = (&rod.structure.model, rod.tip_dof());
    let options = HbOptions {
        harmonics: 10,
        ..HbOptions::default()
    };
    let mut backbone_options = BackboneOptions::new(1, AmplitudeMeasure::Dof(tip), 0.05, 1.5);
    backbone_options.hb = options;
    let branch = backbone(model, &backbone_options).unwrap();
    assert!(matches!(
        branch.termination,
        ContinuationTermination::ReachedBound { .. }
    ));
    let mut epmc = Epmc::new(model, &options, 1, AmplitudeMeasure::Dof(tip)).unwrap();
    let widths = [model.dofs(), model.contact_count()];
    for scale in [0.2, 1.0, 3.0] {
        let mut forced = model.clone();
        forced.load = forced.load.scaled(scale);
        let (dw, dxi, higher) = backbone_against_forced(&branch, &mut epmc, &forced, tip, &widths);
        if scale < 0.5 {
            // Open all period (tip amplitude below the gap): the linear mode 1 against the
            // linear forced response, whose distributed load also drives the other modes
            // off resonance and shifts the tip's phase resonance (measured 6.5e-6 in both).
            assert!(higher == 0.0 && dw < 1e-5 && dxi < 1e-5, "{dw} {dxi}");
        } else {
            // Impacting: the harmonics above the first carry a share `higher` of 0.24 and
            // 0.40 of the velocity; the resonance frequency was measured 1.6e-2 off the
            // backbone at both levels. The damping is not compared: the rod's damping is
            // stiffness-proportional and dissipates the higher harmonics far more than
            // `-xi M u'` does (measured 50 % and 13 % apart).
            assert!(
                dw < 2e-2 && dw < higher * higher,
                "scale {scale}: {dw} {higher}"
            );
        }
    }
}

/// The chain `M = diag(1, 1, 0)`, `K` of the springs ground - 0 - 1 - ground (unit) and 1 - 2
/// (`k_c`), the massless node 2 held by a stop at `gap`, damping `alpha M`, the load
/// `force (1, 1, 0) cos(w t)` along the first mode `(1, 1)` (`omega_1 = 1` while the stop
/// is open).
fn chain_with_stop(gap: f64, k_c: f64, alpha: f64, force: f64) -> StructuralModel {
    StructuralModel {
        mass: sparse(3, &[(0, 0, 1.0), (1, 1, 1.0)]),
        damping: Some(sparse(3, &[(0, 0, alpha), (1, 1, alpha)])),
        stiffness: sparse(
            3,
            &[
                (0, 0, 2.0),
                (0, 1, -1.0),
                (1, 0, -1.0),
                (1, 1, 2.0 + k_c),
                (1, 2, -k_c),
                (2, 1, -k_c),
                (2, 2, k_c),
            ],
        ),
        load: HarmonicLoad::cosine(vec![force, force, 0.0]),
        contacts: vec![ContactPoint::new(2, gap)],
        friction: Vec::new(),
        cyclic: None,
        frictional_contacts: Vec::new(),
    }
}

#[test]
fn chain_backbone_by_energy_carries_the_phase_resonances_of_the_forced_responses() {
    let (gap, k_c, alpha) = (0.5, 3.0, 0.3);
    let options = HbOptions {
        harmonics: 15,
        ..HbOptions::default()
    };
    let free = chain_with_stop(gap, k_c, alpha, 0.0);
    // The energy of the linear mode (1, 1, 1) a cos(w t) is a^2 (module `Epmc::energy`):
    // from a = 0.1 to well past the stop at 0.5.
    let (e_from, e_to) = (0.01, 4.0);
    let mut backbone_options =
        BackboneOptions::by_energy(1, AmplitudeMeasure::Dof(1), e_from, e_to);
    backbone_options.hb = options;
    let branch = backbone(&free, &backbone_options).unwrap();
    let (first, last) = (&branch.points[0], branch.points.last().unwrap());
    // The first point is the linear mode at that energy: w = 1, xi = alpha, a = 0.1.
    assert!((first.energy - e_from).abs() < 1e-14, "{}", first.energy);
    assert!((first.omega - 1.0).abs() < 1e-12 && (first.amplitude - 0.1).abs() < 1e-12);
    // It ends at the first point past the energy bound.
    assert!(matches!(
        branch.termination,
        ContinuationTermination::ReachedBound { bound, .. } if bound == e_to
    ));
    let before = &branch.points[branch.points.len() - 2];
    assert!(
        last.energy >= e_to && before.energy < e_to,
        "{} {}",
        before.energy,
        last.energy
    );
    assert!(
        last.omega > 1.05,
        "the stop stiffens the mode: {}",
        last.omega
    );
    let mut epmc = Epmc::new(&free, &options, 1, AmplitudeMeasure::Dof(1)).unwrap();
    // Force levels whose resonance amplitudes f / alpha are below the gap, at about 2 and
    // 3 gaps.
    for force in [0.09, 0.3, 0.45] {
        let forced = chain_with_stop(gap, k_c, alpha, force);
        let (dw, dxi, higher) = backbone_against_forced(&branch, &mut epmc, &forced, 1, &[3, 1]);
        println!("force {force}: dw {dw:.2e}, dxi {dxi:.2e}, higher {higher:.2e}");
        // Mass-proportional damping is EPMC's `-xi M u'`, so xi = alpha on the backbone
        // and in the forced energy balance alike but for the work of the sampled contact
        // force over a period (truncation); the frequency differs through the harmonics
        // above the first. Both by less than the square of their share `higher`.
        assert!(
            dxi <= higher * higher + 1e-12 && dxi < 1e-3,
            "F {force}: xi {dxi}"
        );
        assert!(
            dw <= higher * higher + 1e-9 && dw < 1e-2,
            "F {force}: w {dw} {higher}"
        );
    }
}

#[test]
fn a_backbone_too_large_for_the_dense_solve_is_refused_before_any_work() {
    let mut options = BackboneOptions::new(1, AmplitudeMeasure::Dof(0), 0.1, 1.0);
    options.hb.harmonics = 2000;
    // (2 dofs + 1 contact) (2 H + 1) + 2 unknowns.
    match backbone(&damped_chain(0.0, 0.0), &options) {
        Err(ModesError::TooLarge { unknowns, limit }) => {
            assert_eq!((unknowns, limit), (3 * 4001 + 2, MAX_DENSE_UNKNOWNS));
        }
        other => panic!("{other:?}"),
    }
    // An amplitude range that is empty is refused too.
    let empty = BackboneOptions::new(1, AmplitudeMeasure::Dof(0), 0.5, 0.5);
    assert!(backbone(&damped_chain(0.0, 0.0), &empty).is_err());
    // So is a dof out of range.
    let outside = BackboneOptions::new(1, AmplitudeMeasure::Dof(7), 0.1, 0.5);
    assert!(backbone(&damped_chain(0.0, 0.0), &outside).is_err());
}

/// The cantilever of `structures::cantilever_with_tip_spring` (beam units, `elements`
/// elements, the pad's spring `kt`), the pad held to the ground by a
/// Coulomb slider of slip force `slip`: a Jenkins element (`kt`, `slip`) on the tip
/// deflection. Damping `alpha M` (the pad is massless: undamped), load `force` times the
/// uniform unit load.
fn beam_with_friction_damper(
    elements: usize,
    kt: f64,
    alpha: f64,
    slip: f64,
    force: f64,
) -> StructuralModel {
    let (k, m, f) = cantilever_with_tip_spring(elements, kt);
    let pad = k.nrows() - 1;
    StructuralModel::new(m, k, f.iter().map(|v| force * v).collect())
        .with_rayleigh_damping(alpha, 0.0)
        .with_friction(FrictionPoint::prescribed(
            ContactRow::unit(pad, 1.0),
            0.5,
            2.0 * slip,
        ))
}

/// `sqrt(1 - |U_1|_M^2 / sum_k k^2 |U_k|_M^2)`: the share of the harmonics above the first
/// in the velocity of the HB unknowns `x` (`n` dofs first).
fn higher_share(mass: &SparseMatrix, x: &[f64], n: usize, harmonics: usize) -> f64 {
    let m = |j: usize| quadratic(mass, &x[j * n..(j + 1) * n]);
    let motion: f64 = (1..=harmonics)
        .map(|k| (k * k) as f64 * (m(2 * k - 1) + m(2 * k)))
        .sum();
    (1.0 - (m(1) + m(2)) / motion).max(0.0).sqrt()
}

#[test]
fn friction_damped_beam_backbone_follows_the_describing_function_and_the_forced_peaks() {
    // A Jenkins element a tenth as stiff as the beam's static tip stiffness (3): stuck,
    // it raises omega_1 from 3.516 to 3.682; it slips from the tip amplitude a_s = 1 on.
    let (elements, kt, alpha, slip) = (10, 0.3, 0.05, 0.3);
    let free = beam_with_friction_damper(elements, kt, alpha, slip, 0.0);
    let n = free.dofs();
    let tip = 2 * elements - 2;
    // c = k_t, the stiffness the slider sees: the default scales with the beam's largest
    // diagonal stiffness (2.4e4 here) and the continuation stalls at the onset of slip.
    let options = HbOptions {
        harmonics: 15,
        c: Some(kt),
        ..HbOptions::default()
    };
    let mut backbone_options = BackboneOptions::new(1, AmplitudeMeasure::Dof(tip), 0.1, 50.0);
    backbone_options.hb = options;
    // The residual rows are forces of the stiffness scale 2.4e4 times amplitudes up to 50:
    // round-off stalls the corrector near 1e-10 (the default), 1e-8 is 1e-14 relative.
    backbone_options.continuation.corrector_tolerance = 1e-8;
    let branch = backbone(&free, &backbone_options).unwrap();
    assert!(
        matches!(
            branch.termination,
            ContinuationTermination::ReachedBound { .. }
        ),
        "{:?}",
        branch.termination
    );
    assert!(branch.points.len() >= 20, "{}", branch.points.len());
    // The reference: the beam without the pad (the pad's spring k_t comes off the tip),
    // its modes by a dense eigensolver, the Jenkins element's describing function on the
    // tip and the secular equation for (w, xi): the single-harmonic mode.
    let (terms, spring) =
        terms_without_slider(&free.stiffness, &free.mass, (alpha, 0.0), tip, n - 1).unwrap();
    assert!((spring - kt).abs() < 1e-12, "{spring}");
    let (mut worst, mut worst_sliding) = ((0.0f64, 0.0f64), 0.0f64);
    for p in &branch.points {
        let r = jenkins_mode(&terms, kt, slip, 1, &[p.amplitude]).unwrap()[0];
        let dw = ((p.omega - r.omega) / r.omega).abs();
        let dxi = ((p.modal_damping - r.modal_damping) / r.modal_damping).abs();
        let higher = higher_share(&free.mass, &p.unknowns, n, options.harmonics);
        assert!(higher < 5e-3, "a {}: {higher}", p.amplitude);
        if p.amplitude < slip / kt {
            // Stuck: the linear mode of the beam with the spring k_t at its tip, to
            // round-off of two eigensolvers.
            assert!(dw < 1e-10 && dxi < 1e-12, "a {}: {dw} {dxi}", p.amplitude);
        }
        worst = (worst.0.max(dw), worst.1.max(dxi));
        if p.amplitude > 10.0 * slip / kt {
            worst_sliding = worst_sliding.max(dxi);
        }
    }
    // The describing function is the one-harmonic limit; the tip's harmonics above the
    // first carry at most 4e-3 of its velocity, so the differences are EPMC's truncation:
    // the slider's kinked motion (coefficients falling like k^-2) at H = 15. Measured
    // largest differences 8.4e-4 in w and 4.1e-2 in xi at H = 7, 4.2e-4 and 3.2e-2 at
    // H = 15, at the onset of slip (a few a_s); beyond 10 a_s xi within 4e-3 (6e-3 asserted).
    println!(
        "largest differences: w {:.1e}, xi {:.1e}; xi beyond 10 a_s {worst_sliding:.1e}",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-3 && worst.1 < 5e-2, "{worst:?}");
    assert!(worst_sliding < 6e-3, "{worst_sliding}");
    let mut epmc = Epmc::new(&free, &options, 1, AmplitudeMeasure::Dof(tip)).unwrap();
    // Resonance amplitudes about 0.5 a_s (stuck), 3 a_s, 10 a_s and 40 a_s.
    for force in [0.06, 0.3, 1.0, 3.0] {
        let forced = beam_with_friction_damper(elements, kt, alpha, slip, force);
        let (dw, dxi, higher) = backbone_against_forced(&branch, &mut epmc, &forced, tip, &[n, 1]);
        // The forced and the EPMC motions differ through the harmonics above the first
        // (share `higher` of the velocity, at most 4e-3) and through the uniform load's
        // drive of the other modes off resonance (the stuck level, higher = 0). Measured
        // below 2.6e-5 in w and xi at every level (5e-5 asserted).
        println!("force {force}: dw {dw:.1e}, dxi {dxi:.1e}, higher {higher:.1e}");
        assert!(
            dw < 5e-5 && dxi < 5e-5,
            "F {force}: w {dw}, xi {dxi}, higher {higher}"
        );
    }
}

/// The largest relative difference between two backbones point by point (`w`, `xi`
/// against `w`, amplitude, energy), after checking they have as many points.
fn backbone_difference(a: &Backbone, b: &Backbone) -> f64 {
    assert_eq!(a.points.len(), b.points.len());
    let relative = |x: f64, y: f64, scale: f64| (x - y).abs() / scale;
    a.points
        .iter()
        .zip(&b.points)
        .map(|(p, q)| {
            relative(p.omega, q.omega, p.omega)
                .max(relative(p.modal_damping, q.modal_damping, p.omega))
                .max(relative(p.amplitude, q.amplitude, p.amplitude))
                .max(relative(p.energy, q.energy, p.energy))
        })
        .fold(0.0, f64::max)
}

#[test]
fn structured_epmc_solve_agrees_with_the_dense_lu_on_stop_and_friction_points() {
    let options = HbOptions {
        harmonics: 7,
        ..HbOptions::default()
    };
    // A point of each backbone in contact (the chain past its stop) and slipping (the
    // Jenkins element past a_s = 1 / 6).
    let cases = [
        (chain_with_stop(0.5, 3.0, 0.3, 0.0), 1, 1.2, 4),
        (jenkins(0.01, 3.0, 0.5, 0.0), 0, 1.0, 3),
    ];
    for (model, dof, amplitude, rows) in cases {
        let measure = AmplitudeMeasure::Dof(dof);
        let mut backbone_options = BackboneOptions::new(1, measure, 0.05, amplitude);
        backbone_options.hb = options;
        let branch = backbone(&model, &backbone_options).unwrap();
        let x = &branch.points.last().unwrap().unknowns;
        let mut plain = Epmc::new(&model, &options, 1, measure).unwrap();
        let mut deflated = Epmc::deflated(&model, &options, 1, measure).unwrap();
        assert!(deflated.is_deflated() && !plain.is_deflated());
        let len = plain.dim();
        assert_eq!(len, rows * (2 * options.harmonics + 1) + 2);
        // The same residual and the same dense Jacobian: the grounding spring is taken out
        // again (round-off of adding and subtracting s = 4 or 5 to entries of that size).
        let (mut r, mut r_deflated) = (vec![0.0; len], vec![0.0; len]);
        plain.residual(x, &mut r).unwrap();
        deflated.residual(x, &mut r_deflated).unwrap();
        assert!(common::max_abs_diff(&r, &r_deflated) < 1e-13);
        let (mut j, mut j_deflated) = (plain.new_jacobian(), deflated.new_jacobian());
        plain.jacobian(x, &mut j).unwrap();
        deflated.jacobian(x, &mut j_deflated).unwrap();
        let (mut a, mut b) = (Mat::zeros(len, len), Mat::zeros(len, len));
        j.assemble_dense(a.as_mut());
        j_deflated.assemble_dense(b.as_mut());
        assert!((&a - &b).norm_max() < 1e-13 * a.norm_max());
        // A right-hand side with every entry nonzero, solved both ways.
        let rhs: Vec<f64> = (0..len)
            .map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.01)
            .collect();
        let (mut dense, mut structured) = (rhs.clone(), rhs.clone());
        let mut lu = FaerDenseLu::new();
        lu.factor(&a).unwrap();
        lu.solve_in_place(&mut dense).unwrap();
        let mut solver = EpmcStructuredSolver::new();
        solver.factor(&j_deflated).unwrap();
        solver.solve_in_place(&mut structured).unwrap();
        // One inner factorization, 2H + 3 border solves and one for the right-hand side.
        let counters = solver.counters();
        assert_eq!(counters.factorizations, 1);
        assert_eq!(counters.solves, 2 * options.harmonics as u64 + 4);
        // Both are backward stable on a matrix of condition ~1e4 (entries up to 5, the
        // frequency columns of the size of the forces): agreement to 1e-10 of the solution.
        let error = common::max_abs_diff(&dense, &structured) / common::max_abs(&dense);
        println!("structured against dense: {error:.1e}");
        assert!(error < 1e-10, "{error}");
        // The plain problem has no regular inner block: refused, not solved wrongly.
        assert!(EpmcStructuredSolver::new().factor(&j).is_err());
    }
}

#[test]
fn structured_backbone_is_the_dense_backbone_on_stop_and_friction() {
    let options = HbOptions {
        harmonics: 7,
        ..HbOptions::default()
    };
    let cases = [
        (chain_with_stop(0.5, 3.0, 0.3, 0.0), 1, 1.5),
        (jenkins(0.01, 3.0, 0.5, 0.0), 0, 3.0),
    ];
    for (model, dof, amplitude) in cases {
        let mut dense = BackboneOptions::new(1, AmplitudeMeasure::Dof(dof), 0.05, amplitude);
        dense.hb = options;
        let mut structured = dense.clone();
        structured.solve = EpmcSolve::Structured;
        let (a, b) = (
            backbone(&model, &dense).unwrap(),
            backbone(&model, &structured).unwrap(),
        );
        assert!(matches!(
            b.termination,
            ContinuationTermination::ReachedBound { .. }
        ));
        assert!(a.points.len() >= 10, "{}", a.points.len());
        // The corrections differ by round-off (previous test) and Newton converges
        // quadratically: the accepted points agree far below the corrector's tolerance.
        let difference = backbone_difference(&a, &b);
        println!(
            "{} points, largest difference {difference:.1e}",
            a.points.len()
        );
        assert!(difference < 1e-10, "{difference}");
    }
}

/// [`chain_with_stop`] in other units: stiffness `k` (N/m per unit), mass `m` (kg per
/// unit), length `l` (m per unit); `w` scales by `sqrt(k / m)`, damping by `sqrt(k m)`.
fn chain_with_stop_in_units(
    gap: f64,
    k_c: f64,
    alpha: f64,
    (k, m, l): (f64, f64, f64),
) -> StructuralModel {
    let model = chain_with_stop(gap * l, k_c, alpha * (k / m).sqrt(), 0.0);
    let scale = |a: &SparseMatrix, s: f64| {
        let entries: Vec<(usize, usize, f64)> = (0..a.ncols())
            .flat_map(|j| {
                a.symbolic()
                    .col_range(j)
                    .map(move |q| (a.symbolic().row_idx()[q], j, s * a.val()[q]))
            })
            .collect();
        sparse(a.nrows(), &entries)
    };
    StructuralModel {
        mass: scale(&model.mass, m),
        damping: model.damping.as_ref().map(|d| scale(d, m)),
        stiffness: scale(&model.stiffness, k),
        ..model
    }
}

#[test]
fn a_model_in_si_units_follows_the_backbone_of_its_nondimensional_twin() {
    // Stiffness 1e9 N/m, mass 1e3 kg, length 1e-6 m: forces of 1e3 N, w 1e3 times larger.
    // With the corrector's tolerance absolute the twin's residuals (1e3 times larger) could
    // not meet it; relative to the force scale both runs take the same decisions.
    let units = (1e9, 1e3, 1e-6);
    let (gap, k_c, alpha) = (0.5, 3.0, 0.3);
    let options = HbOptions {
        harmonics: 7,
        ..HbOptions::default()
    };
    let plain = chain_with_stop_in_units(gap, k_c, alpha, (1.0, 1.0, 1.0));
    let si = chain_with_stop_in_units(gap, k_c, alpha, units);
    let mut reference = BackboneOptions::new(1, AmplitudeMeasure::Dof(1), 0.1, 1.5);
    reference.hb = options;
    let mut twin = BackboneOptions::new(1, AmplitudeMeasure::Dof(1), 0.1 * units.2, 1.5 * units.2);
    twin.hb = options;
    let (a, b) = (
        backbone(&plain, &reference).unwrap(),
        backbone(&si, &twin).unwrap(),
    );
    assert!(matches!(
        b.termination,
        ContinuationTermination::ReachedBound { .. }
    ));
    assert_eq!(a.points.len(), b.points.len());
    let (w, energy) = ((units.0 / units.1).sqrt(), units.0 * units.2 * units.2);
    let mut worst = 0.0f64;
    for (p, q) in a.points.iter().zip(&b.points) {
        let relative = |x: f64, y: f64| (x - y).abs() / x.abs().max(f64::MIN_POSITIVE);
        worst = worst
            .max(relative(p.omega, q.omega / w))
            .max(relative(p.amplitude, q.amplitude / units.2))
            .max(relative(p.energy, q.energy / energy))
            .max((p.damping_ratio - q.damping_ratio).abs());
    }
    // Round-off: the same iterations on numbers scaled by powers of ten (not exact in
    // binary), each a few ulps apart, through a handful of Newton steps per point.
    println!("{} points, largest difference {worst:.1e}", a.points.len());
    assert!(worst < 1e-10, "{worst}");
}

/// `(w, xi)` of the EPMC of `model` with `options` at each of `amplitudes` (measured at
/// `dof`), by Newton from the nearest point of `branch`.
fn epmc_at(
    model: &StructuralModel,
    options: &HbOptions,
    dof: usize,
    branch: &Backbone,
    amplitudes: &[f64],
) -> Vec<(f64, f64)> {
    let mut epmc = Epmc::new(model, options, 1, AmplitudeMeasure::Dof(dof)).unwrap();
    amplitudes
        .iter()
        .map(|&a| {
            let distance = |p: &BackbonePoint| (p.amplitude - a).abs();
            let nearest = (branch.points.iter())
                .min_by(|p, q| distance(p).total_cmp(&distance(q)))
                .unwrap();
            let mut x = nearest.unknowns.clone();
            epmc.set_parameter(a);
            let newton = PolyalgorithmOptions::default();
            let report = polyalgorithm::solve(&mut epmc, &mut FaerDenseLu::new(), &mut x, &newton);
            assert!(report.unwrap().converged(), "a {a}");
            (epmc.omega(&x), epmc.modal_damping(&x))
        })
        .collect()
}

#[test]
fn friction_backbone_depends_on_the_augmentation_constant_only_through_the_truncation() {
    // The Jenkins element (k_t = 3, slip from a_s = 1/6): stuck at 0.1, slipping part of
    // the period at 0.3 and 1, most of it at 2.5. c = 3 is the slider's stiffness; 0.3 and
    // 30 are ten times off.
    let model = jenkins(0.01, 3.0, 0.5, 0.0);
    let (stuck, slipping) = (0.1, [0.3, 1.0, 2.5]);
    let mut worst = Vec::new();
    for harmonics in [7, 15] {
        let options = |c: f64| HbOptions {
            harmonics,
            c: Some(c),
            ..HbOptions::default()
        };
        let mut backbone_options = BackboneOptions::new(1, AmplitudeMeasure::Dof(0), 0.05, 3.0);
        backbone_options.hb = options(3.0);
        let branch = backbone(&model, &backbone_options).unwrap();
        let amplitudes = [&[stuck][..], &slipping].concat();
        let reference = epmc_at(&model, &options(3.0), 0, &branch, &amplitudes);
        let mut largest = 0.0f64;
        for c in [0.3, 30.0] {
            let other = epmc_at(&model, &options(c), 0, &branch, &amplitudes);
            let difference = |i: usize| {
                let ((w, xi), (w_c, xi_c)) = (reference[i], other[i]);
                ((w - w_c) / w).abs().max(((xi - xi_c) / w).abs())
            };
            // Stuck, the law holds at every sample whatever c: the same linear mode.
            assert!(
                difference(0) < 1e-14,
                "H = {harmonics}, c {c}: {}",
                difference(0)
            );
            largest = (1..amplitudes.len())
                .map(difference)
                .fold(largest, f64::max);
        }
        println!("H = {harmonics}: largest relative difference over c {largest:.1e}");
        worst.push(largest);
    }
    // Slipping, the law is met in the Galerkin sense only (Nt > 2H + 1 samples, projected
    // on 2H + 1 harmonics), and the projected residual of the kinked slider force depends
    // on c: the solutions differ by a truncation error. Measured 3.4e-2 at H = 7 and
    // 8.1e-3 at H = 15 (a factor 4 per doubling of H, the order of the slider's kinks):
    // asserted shrinking by at least 3 and below 1e-2 at H = 15.
    assert!(worst[1] < worst[0] / 3.0 && worst[1] < 1e-2, "{worst:?}");
}
