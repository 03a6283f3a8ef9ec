//! Forward model -> each estimator -> R_r, R_a over a dense grid, with the error figures
//! that docs/accuracy.md quotes. Run with `--nocapture` to see the table:
//! `cargo test -p estimator-core --test round_trip -- --nocapture`.

use estimator_core::forward::Operating;
use estimator_core::geometry::RR_MIN;
use estimator_core::table3::{self, Branch};
use estimator_core::{
    average_forces, Engagement, EstimatorConfig, Measured, Method, MillingMode, Solver, TABLE2,
};

/// Feeds 0.02..0.5 mm/tooth, log-spaced, plus the paper's three.
fn feeds() -> Vec<f32> {
    let mut v: Vec<f32> = (0..25)
        .map(|i| (0.02f64.ln() + (0.5f64 / 0.02).ln() * i as f64 / 24.0).exp() as f32)
        .collect();
    v.extend([0.1042, 0.2083, 0.4167]);
    v
}

/// Radial immersions `lo..=2` in steps of 0.01.
fn immersions(lo: f32) -> Vec<f32> {
    let n = ((2.0 - lo) / 0.01).round() as usize;
    (0..=n)
        .map(|i| lo + (2.0 - lo) * i as f32 / n as f32)
        .collect()
}

#[derive(Default)]
struct Errors(Vec<f64>);

impl Errors {
    fn push(&mut self, est: f32, truth: f32) {
        self.0.push(((est - truth) / truth).abs() as f64);
    }
    fn p95(&self) -> f64 {
        let mut v = self.0.clone();
        v.sort_by(f64::total_cmp);
        v[((v.len() as f64 * 0.95).ceil() as usize).min(v.len()) - 1]
    }
    fn max(&self) -> f64 {
        self.0.iter().copied().fold(0.0, f64::max)
    }
    fn report(&self, what: &str) {
        println!(
            "{what:<58} n={:>5}  p95 {:>7.3} %  max {:>7.3} %",
            self.0.len(),
            100.0 * self.p95(),
            100.0 * self.max()
        );
    }
}

/// Runs one solver over the grid; returns R_r and R_a errors.
fn sweep(
    mode: MillingMode,
    solver: Solver,
    dynamometer: bool,
    rr_lo: f32,
    expect: Method,
) -> (Errors, Errors) {
    let est = EstimatorConfig {
        mode,
        solver,
        ..Default::default()
    }
    .build()
    .expect("valid config");
    let tool = est.config().tool;
    let (mut e_rr, mut e_ra) = (Errors::default(), Errors::default());
    for tc in feeds() {
        for rr in immersions(rr_lo) {
            let ra = 1.25;
            let f = average_forces(&tool, &TABLE2, mode, Engagement { rr, ra, tc_mm: tc });
            let m = if dynamometer {
                Measured::Dynamometer {
                    fx_n: f.fx_n,
                    fy_n: f.fy_n,
                }
            } else {
                Measured::Motor {
                    fx_n: f.fx_n,
                    ft_n: f.ft_n,
                }
            };
            let e = est.estimate(tc, m);
            assert_eq!(e.method, expect, "{mode:?} {solver:?} rr {rr} tc {tc}");
            e_rr.push(e.rr, rr);
            e_ra.push(e.ra, ra);
        }
    }
    (e_rr, e_ra)
}

#[test]
fn fitted_polynomial_meets_its_accuracy_goal() {
    // Goal (issue): p95 < 0.5 %, max < 2 % over t_c 0.02-0.5 and R_r 0.1-2, down milling.
    let (rr, ra) = sweep(
        MillingMode::Down,
        Solver::Polynomial,
        false,
        0.1,
        Method::Polynomial,
    );
    rr.report("f_xt polynomial, down, R_r 0.1-2: R_r");
    ra.report("f_xt polynomial, down, R_r 0.1-2: R_a");
    assert!(rr.p95() < 0.005 && rr.max() < 0.02);
    assert!(ra.p95() < 0.005 && ra.max() < 0.02);
    // Up milling: fitted where f_xt is monotonic and well conditioned (R_r >= 0.5).
    let (rr, ra) = sweep(
        MillingMode::Up,
        Solver::Polynomial,
        false,
        0.5,
        Method::Polynomial,
    );
    rr.report("f_xt polynomial, up, R_r 0.5-2: R_r");
    ra.report("f_xt polynomial, up, R_r 0.5-2: R_a");
    assert!(rr.p95() < 0.005 && rr.max() < 0.02);
    assert!(ra.p95() < 0.005 && ra.max() < 0.02);
}

#[test]
fn exact_inversion_is_exact() {
    for (mode, dyn_, lo, what) in [
        (
            MillingMode::Down,
            false,
            0.02,
            "inversion f_xt, down, R_r 0.02-2",
        ),
        (MillingMode::Up, false, 0.3, "inversion f_xt, up, R_r 0.3-2"),
        (
            MillingMode::Down,
            true,
            0.1,
            "inversion f_x, down, R_r 0.1-2",
        ),
    ] {
        let (rr, ra) = sweep(mode, Solver::Inversion, dyn_, lo, Method::Inversion);
        rr.report(&format!("{what}: R_r"));
        ra.report(&format!("{what}: R_a"));
        assert!(rr.max() < 2e-3 && ra.max() < 2e-3, "{what}");
    }
}

#[test]
fn table3_as_published_reproduces_eq10() {
    // method.md: within about 3 % for R_r >= 0.125 over t_c 0.02-0.5; degrades below 0.1.
    let (rr, _) = sweep(
        MillingMode::Down,
        Solver::Table3,
        true,
        0.125,
        Method::Table3,
    );
    rr.report("Table 3 (paper), f_x, down, R_r 0.125-2: R_r");
    assert!(
        rr.max() < 0.04,
        "Table 3 max error {:.2} %",
        100.0 * rr.max()
    );
    let (low, _) = sweep(
        MillingMode::Down,
        Solver::Table3,
        true,
        0.05,
        Method::Table3,
    );
    low.report("Table 3 (paper), f_x, down, R_r 0.05-2: R_r");
    // Its exact value at R_r = 1 (the paper's own check point).
    for tc in feeds() {
        let op = Operating::new(&TABLE2, MillingMode::Down, 1.0, tc);
        let rr = table3::rr_from_fx(op.ratio_fx(), tc, Branch::Auto);
        assert!(
            (rr - 1.0).abs() < 0.02,
            "tc {tc}: Table 3 gives {rr} at R_r = 1"
        );
    }
}

#[test]
fn table3_branch_must_follow_tc() {
    // The wrong row is far off: the low-t_c row above 0.08 diverges, the high row below it
    // is off by tens of %. Worst error over R_r 0.25-2 for the wrong row, each side.
    let worst = |tcs: &[f32], branch| {
        let mut w = 0.0f32;
        for &tc in tcs {
            for rr in immersions(0.25) {
                let f = Operating::new(&TABLE2, MillingMode::Down, rr, tc).ratio_fx();
                w = w.max(((table3::rr_from_fx(f, tc, branch) - rr) / rr).abs());
            }
        }
        w
    };
    assert!(worst(&[0.2, 0.3, 0.45], Branch::LowTc) > 1.0);
    assert!(worst(&[0.02, 0.03, 0.05], Branch::HighTc) > 0.1);
}

#[test]
fn fxt_rises_strictly_in_down_milling() {
    // The property that lets the inversion skip the turning-point search in this case.
    for tc in feeds() {
        let mut prev = f32::NEG_INFINITY;
        for i in 0..=2000 {
            let rr = RR_MIN + (2.0 - RR_MIN) * i as f32 / 2000.0;
            let f = Operating::new(&TABLE2, MillingMode::Down, rr, tc).ratio_fxt();
            assert!(f > prev, "tc {tc}: f_xt not rising at R_r {rr}");
            prev = f;
        }
        // Limits from method.md: -1 as R_r -> 0, r1 pi / 4 in the slot.
        let slot = Operating::new(&TABLE2, MillingMode::Down, 2.0, tc);
        assert!((slot.ratio_fxt() - slot.r1 * core::f32::consts::FRAC_PI_4).abs() < 1e-5);
        let light = Operating::new(&TABLE2, MillingMode::Down, RR_MIN, tc).ratio_fxt();
        // r1 b / c -> 0 only slowly (r1 grows as t_a^-0.27), hence the loose bound.
        assert!(light > -1.0 && light < -0.9, "tc {tc}: {light}");
    }
}
