//! The `f_xt` polynomials of calibrated coefficients (`ESTIMATOR_FXT_POLY` at build time,
//! see build.rs): without it none are compiled in; with it each one is found by the
//! estimator for its coefficients and inverts their forward model. CI builds this test with
//! the polynomial its calibration test wrote (tests/all.sh).

use estimator_core::forward::Operating;
use estimator_core::fxt_poly_user::ALL;
use estimator_core::{EstimatorConfig, Measured, Method};

#[test]
fn calibrated_polynomials_are_compiled_in_and_used() {
    let Some(path) = option_env!("ESTIMATOR_FXT_POLY") else {
        assert!(ALL.is_empty(), "polynomials without ESTIMATOR_FXT_POLY");
        return;
    };
    assert!(!ALL.is_empty(), "{path} holds no polynomial");
    for p in ALL {
        let est = EstimatorConfig {
            coeffs: p.coeffs,
            mode: p.mode,
            ..EstimatorConfig::default()
        }
        .build()
        .expect("builds");
        assert!(est.has_polynomial(), "{:?}: not found", p.mode);
        // The forward model at a few points inside the set's range, back through it.
        for rr in [p.rr.0 * 1.5, 0.5 * (p.rr.0 + p.rr.1), p.rr.1 * 0.95] {
            let tc = (p.tc_mm.0 * p.tc_mm.1).sqrt();
            let op = Operating::new(&p.coeffs, p.mode, rr, tc);
            let f = op.forces(&p.coeffs, &est.config().tool, tc, 0.5);
            let e = est.estimate(
                tc,
                Measured::Motor {
                    fx_n: f.fx_n,
                    ft_n: f.ft_n,
                },
            );
            assert_eq!(e.method, Method::Polynomial, "{:?} rr {rr}", p.mode);
            assert!(
                (e.rr / rr - 1.0).abs() < 0.02,
                "{:?}: rr {rr} -> {}",
                p.mode,
                e.rr
            );
        }
    }
}
