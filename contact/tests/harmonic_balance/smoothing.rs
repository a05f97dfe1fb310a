//! The smoothed semismooth equation: its Jacobian and its derivative in the smoothing
//! parameter against central differences, and zero smoothing as the formulation itself.

use super::*;

#[test]
fn smoothed_ssn_jacobian_and_mu_derivative_match_central_differences() {
    let (model, omega) = chain(3, Some(0.02), 0.9, contacts(&[(1, 0.2), (2, 0.1)]));
    let (h, nt) = (3, 16);
    let mut hb = SsnHb::new(&model, omega, &hb_options(h, Some(nt), Some(2.0))).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let x = random_vector(&mut rng, hb.dim(), 0.5);
    let mu = 0.05;
    hb.set_smoothing(mu);
    // F_mu is smooth everywhere (no kink to avoid); its second derivative is at most of
    // order c^2 / mu = 80, so the central difference with step 1e-6 errs by ~1e-10
    // relative, and rounding (eps |F| / step) by ~1e-10 too. Measured 3.3e-11 (Jacobian) and
    // 1.9e-10 (mu derivative); asserted at 1e-9, ten times the estimate.
    let mut jac = hb.new_jacobian();
    hb.jacobian(&x, &mut jac).unwrap();
    let analytic = assemble(&jac);
    let fd = fd_jacobian(&mut hb, &x, 1e-6);
    let err = max_abs(&(&analytic - &fd)) / max_abs(&analytic);
    println!("smoothed: relative Jacobian error against central differences: {err:.2e}");
    assert!(err < 1e-9, "relative Jacobian error {err:e}");

    let n = hb.dim();
    let mut analytic = vec![0.0; n];
    hb.residual_smoothing_derivative(&x, &mut analytic).unwrap();
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let step = 1e-6;
    hb.set_smoothing(mu + step);
    hb.residual(&x, &mut fp).unwrap();
    hb.set_smoothing(mu - step);
    hb.residual(&x, &mut fm).unwrap();
    let diff: Vec<f64> = analytic
        .iter()
        .zip(fp.iter().zip(&fm))
        .map(|(a, (p, m))| a - (p - m) / (2.0 * step))
        .collect();
    assert!(norm(&analytic) > 0.0);
    println!(
        "smoothed: relative mu-derivative error: {:.2e}",
        norm(&diff) / norm(&analytic)
    );
    assert!(
        norm(&diff) < 1e-9 * norm(&analytic),
        "{:e}",
        norm(&diff) / norm(&analytic)
    );
}

#[test]
fn zero_smoothing_is_the_formulation_itself_and_small_smoothing_is_within_mu() {
    let (model, omega) = chain(3, Some(0.02), 0.9, contacts(&[(1, 0.2), (2, 0.1)]));
    let (h, nt) = (3, 16);
    let mut plain = SsnHb::new(&model, omega, &hb_options(h, Some(nt), Some(2.0))).unwrap();
    let mut smoothed = SsnHb::new(&model, omega, &hb_options(h, Some(nt), Some(2.0))).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let x = random_vector(&mut rng, plain.dim(), 0.5);
    let n = plain.dim();
    let (mut f0, mut f) = (vec![0.0; n], vec![0.0; n]);
    plain.residual(&x, &mut f0).unwrap();
    smoothed.set_smoothing(0.3);
    smoothed.residual(&x, &mut f).unwrap();
    assert!(f != f0);
    smoothed.set_smoothing(0.0);
    smoothed.residual(&x, &mut f).unwrap();
    assert_eq!(f, f0);
    // 0 <= phi_mu(s) - max(0, s) <= mu at every sample, so each force coefficient moves by
    // at most mu times the 1-norm of a row of P (<= 2) and the displacement rows not at all.
    let mu = 1e-3;
    smoothed.set_smoothing(mu);
    smoothed.residual(&x, &mut f).unwrap();
    let largest = f
        .iter()
        .zip(&f0)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(largest > 0.0 && largest <= 2.0 * mu, "{largest:e}");
}
