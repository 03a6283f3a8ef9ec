//! The whole signal chain on synthetic motor currents: closed-form instantaneous forces
//! (tests/common) through drive models with lag and noise, encoder pulses, into the
//! Monitor; estimates checked against the cut that produced them.

#![allow(clippy::unwrap_used)]

mod common;

use common::{instantaneous, Rng};
use estimator_core::drive::{FeedAxis, FeedDrive, SpindleModel};
use estimator_core::monitor::Input;
use estimator_core::table::{Segment, Segments};
use estimator_core::tooth::SyncMode;
use estimator_core::{
    EstimatorConfig, MillingMode, Monitor, MonitorConfig, MonitorState, Sample, Status,
    ToothRecord, TABLE2,
};
use std::f64::consts::PI;

/// A steady stretch of cutting (or air, with `dr_mm = 0`).
#[derive(Clone, Copy, Debug)]
struct Seg {
    dur_s: f64,
    dr_mm: f64,
    da_mm: f64,
    feed_mm_min: f64,
    rpm: f64,
}

struct Scenario {
    mode: MillingMode,
    fs: f64,
    segs: Vec<Seg>,
    /// Tooth-average force noise, relative to the tangential force.
    noise_rel: f64,
    /// Radial offset of each flute [mm] (runout).
    runout_mm: [f64; 4],
    /// First-order current-loop lag [s].
    lag_s: f64,
    seed: u64,
}

fn feed_axis() -> FeedAxis {
    FeedAxis {
        torque_constant_nm_per_a: 1.2,
        screw_lead_mm: 10.0,
        efficiency: 0.9,
        current_offset_a: 0.05,
        coulomb_n: 40.0,
        viscous_n_per_mm_min: 0.02,
        stiction_band_mm_min: 1.0,
        sign: 1.0,
    }
}

fn spindle() -> SpindleModel {
    SpindleModel::Current {
        torque_constant_nm_per_a: 0.8,
        idle_current_a: Segments::new(&[Segment {
            from_rpm: 0.0,
            slope: 1e-4,
            intercept: 0.5,
        }])
        .unwrap(),
    }
}

fn config(mode: MillingMode, fs: f64) -> MonitorConfig {
    MonitorConfig {
        sample_rate_hz: fs as f32,
        input: Input::Motor {
            feed: FeedDrive {
                axes: [feed_axis(), feed_axis()],
                two_axis: false,
            },
            spindle: spindle(),
        },
        estimator: EstimatorConfig {
            mode,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// What the cut was at a sample.
#[derive(Clone, Copy, Debug)]
struct Truth {
    seg: usize,
    dr_mm: f64,
    da_mm: f64,
}

/// Generates the scenario's samples and hands each (with its truth) to `f`.
fn generate(sc: &Scenario, mut f: impl FnMut(&Sample, Truth)) {
    let tool = EstimatorConfig::default().tool;
    let n = tool.flutes as usize;
    let r = tool.radius_mm as f64;
    let feed = FeedDrive {
        axes: [feed_axis(), feed_axis()],
        two_axis: false,
    };
    let sp = spindle();
    let dt = 1.0 / sc.fs;
    let mut rng = Rng::new(sc.seed);
    let (mut theta, mut i_feed, mut i_sp) = (0.0f64, f64::NAN, f64::NAN);
    let mut last_tooth = 0i64;
    for (k, seg) in sc.segs.iter().enumerate() {
        let tc = seg.feed_mm_min / (n as f64 * seg.rpm);
        // Runout: flute j cuts the chip left by flute j-1 plus the difference of offsets.
        let tcs: Vec<f64> = (0..n)
            .map(|j| tc + sc.runout_mm[j] - sc.runout_mm[(j + n - 1) % n])
            .collect();
        let steps = (seg.dur_s * sc.fs).round() as usize;
        let samples_per_tooth = sc.fs * 60.0 / (seg.rpm * n as f64);
        // Per-sample noise that leaves `noise_rel` on a tooth average.
        let rr = seg.dr_mm / r;
        let cutting = seg.dr_mm > 0.0 && seg.da_mm > 0.0;
        let ft_mean = if cutting {
            estimator_core::average_forces(
                &tool,
                &TABLE2,
                sc.mode,
                estimator_core::Engagement {
                    rr: rr as f32,
                    ra: (seg.da_mm / r) as f32,
                    tc_mm: tc as f32,
                },
            )
            .ft_n as f64
        } else {
            0.0
        };
        let sigma_n = sc.noise_rel * ft_mean * samples_per_tooth.sqrt();
        for _ in 0..steps {
            theta += 2.0 * PI * seg.rpm / 60.0 * dt;
            let tooth = (theta / (2.0 * PI / n as f64)).floor() as i64;
            let sync = tooth != last_tooth;
            last_tooth = tooth;
            let (ft, fx, _fy) = if cutting {
                instantaneous(&tool, &TABLE2, sc.mode, rr, seg.da_mm / r, tc, &tcs, theta)
            } else {
                (0.0, 0.0, 0.0)
            };
            let fx = fx + sigma_n * rng.gauss();
            let ft = ft + sigma_n * rng.gauss();
            let v = [seg.feed_mm_min as f32, 0.0];
            let target_feed = feed.currents_for_loads_a([fx as f32, 0.0], v)[0] as f64;
            let target_sp = sp.signal_for_force(ft as f32, seg.rpm as f32, r as f32) as f64;
            // Current loop: first-order lag (exact discretisation).
            let a = if sc.lag_s > 0.0 {
                (-dt / sc.lag_s).exp()
            } else {
                0.0
            };
            i_feed = if i_feed.is_nan() {
                target_feed
            } else {
                a * i_feed + (1.0 - a) * target_feed
            };
            i_sp = if i_sp.is_nan() {
                target_sp
            } else {
                a * i_sp + (1.0 - a) * target_sp
            };
            let s = Sample {
                feed: [i_feed as f32, 0.0],
                feed_velocity_mm_min: v,
                spindle: i_sp as f32,
                sync,
            };
            f(
                &s,
                Truth {
                    seg: k,
                    dr_mm: seg.dr_mm,
                    da_mm: seg.da_mm,
                },
            );
        }
    }
}

/// Runs the monitor over a scenario; returns records with the truth at their end.
fn run(sc: &Scenario, cfg: MonitorConfig) -> Vec<(ToothRecord, Truth)> {
    run_with(sc, cfg, |_, _| {})
}

/// Same, letting `tamper(sample_index, sample)` break the input first.
fn run_with(
    sc: &Scenario,
    cfg: MonitorConfig,
    mut tamper: impl FnMut(usize, &mut Sample),
) -> Vec<(ToothRecord, Truth)> {
    let mon: Monitor = cfg.build().expect("valid config");
    let mut st = MonitorState::default();
    let mut out = Vec::new();
    let mut i = 0;
    generate(sc, |s, truth| {
        let mut s = *s;
        tamper(i, &mut s);
        i += 1;
        if let Some(rec) = mon.process(&mut st, &s) {
            out.push((rec, truth));
        }
    });
    out
}

/// A scenario at the paper's 600 rpm, 10 kS/s, 1 % noise, slight runout and lag.
fn paper(segs: Vec<Seg>, seed: u64) -> Scenario {
    Scenario {
        mode: MillingMode::Down,
        fs: 10_000.0,
        segs,
        noise_rel: 0.01,
        runout_mm: [0.01, 0.0, 0.0, 0.0],
        lag_s: 5e-4,
        seed,
    }
}

fn seg(dur_s: f64, dr_mm: f64, da_mm: f64, feed_mm_min: f64) -> Seg {
    Seg {
        dur_s,
        dr_mm,
        da_mm,
        feed_mm_min,
        rpm: 600.0,
    }
}

/// Every record reported valid is within `tol` of the truth; returns how many were valid.
/// "The truth" of a filtered estimate is whatever the cut was over the filter window (the
/// last 16 teeth): the estimate must lie within `tol` of that range.
fn valid_ones_are_right(recs: &[(ToothRecord, Truth)], tol: f64) -> usize {
    let mut n = 0;
    for (i, (r, t)) in recs.iter().enumerate() {
        if r.status.is_valid() {
            n += 1;
            let window = &recs[i.saturating_sub(15)..=i];
            let range = |f: fn(&Truth) -> f64| {
                window
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(lo, hi), (_, t)| {
                        (lo.min(f(t)), hi.max(f(t)))
                    })
            };
            assert!(
                range(|t| t.dr_mm).0 > 0.0,
                "valid record over an air cut: {r:?}"
            );
            let off = |v: f32, (lo, hi): (f64, f64)| {
                let v = v as f64;
                (if v < lo {
                    (lo - v) / lo
                } else if v > hi {
                    (v - hi) / hi
                } else {
                    0.0
                })
                .abs()
            };
            let (e_dr, e_da) = (
                off(r.dr_mm, range(|t| t.dr_mm)),
                off(r.da_mm, range(|t| t.da_mm)),
            );
            assert!(
                e_dr < tol && e_da < tol,
                "valid but wrong (truth {t:?}): {r:?}"
            );
        } else {
            assert_eq!(
                (r.dr_mm, r.da_mm, r.rr, r.ra),
                (0.0, 0.0, 0.0, 0.0),
                "{r:?}"
            );
        }
    }
    n
}

/// Statuses seen in records whose end falls in segment `k`.
fn flags_in(recs: &[(ToothRecord, Truth)], k: usize) -> Status {
    recs.iter()
        .filter(|(_, t)| t.seg == k)
        .fold(Status::VALID, |a, (r, _)| a | r.status)
}

fn p95(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * 0.95).ceil() as usize).min(v.len()) - 1]
}

#[test]
fn paper_conditions_within_5_percent_p95_at_1_percent_noise() {
    let mut err_dr = Vec::new();
    let mut err_da = Vec::new();
    let (mut inside_2sigma, mut total) = (0usize, 0usize);
    let mut seed = 1;
    for mode in [MillingMode::Down] {
        for tc in [0.1042, 0.2083, 0.4167] {
            for dr in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0] {
                for da in [2.0, 6.0, 11.0, 16.0] {
                    seed += 1;
                    let sc = Scenario {
                        mode,
                        fs: 10_000.0,
                        segs: vec![Seg {
                            dur_s: 2.5,
                            dr_mm: dr,
                            da_mm: da,
                            feed_mm_min: tc * 4.0 * 600.0,
                            rpm: 600.0,
                        }],
                        noise_rel: 0.01,
                        runout_mm: [0.01, 0.0, 0.0, 0.0],
                        lag_s: 5e-4,
                        seed,
                    };
                    let recs = run(&sc, config(mode, sc.fs));
                    let valid: Vec<_> = recs.iter().filter(|(r, _)| r.status.is_valid()).collect();
                    assert!(
                        valid.len() >= 40,
                        "tc {tc} dr {dr} da {da}: only {} valid of {}",
                        valid.len(),
                        recs.len()
                    );
                    for (r, t) in valid {
                        let e_dr = (r.dr_mm as f64 - t.dr_mm) / t.dr_mm;
                        let e_da = (r.da_mm as f64 - t.da_mm) / t.da_mm;
                        err_dr.push(e_dr.abs());
                        err_da.push(e_da.abs());
                        total += 1;
                        if (r.dr_mm as f64 - t.dr_mm).abs() <= 2.0 * r.dr_sigma_mm as f64 {
                            inside_2sigma += 1;
                        }
                    }
                }
            }
        }
    }
    let (p_dr, p_da) = (p95(err_dr.clone()), p95(err_da.clone()));
    let max_dr = err_dr.iter().copied().fold(0.0, f64::max);
    let coverage = inside_2sigma as f64 / total as f64;
    println!(
        "paper conditions, 1 % noise: {total} valid records, d_r p95 {:.2} % (max {:.2} %), d_a p95 {:.2} %, inside 2 sigma {:.0} %",
        100.0 * p_dr, 100.0 * max_dr, 100.0 * p_da, 100.0 * coverage
    );
    assert!(p_dr < 0.05 && p_da < 0.05);
    // The reported uncertainty must mean something: roughly 95 % inside 2 sigma.
    assert!(
        coverage > 0.8,
        "only {:.0} % of d_r errors inside 2 sigma",
        100.0 * coverage
    );
}

#[test]
fn entry_and_exit_are_flagged_not_reported() {
    // Air, a radial entry ramp over 5 revolutions, a steady cut, a ramp out, air.
    let mut segs = vec![seg(0.5, 0.0, 6.0, 250.0)];
    for k in 1..=20 {
        segs.push(seg(0.025, 4.0 * k as f64 / 20.0, 6.0, 250.0));
    }
    segs.push(seg(2.5, 4.0, 6.0, 250.0));
    for k in (0..20).rev() {
        segs.push(seg(0.025, 4.0 * k as f64 / 20.0, 6.0, 250.0));
    }
    segs.push(seg(0.5, 0.0, 6.0, 250.0));
    let recs = run(&paper(segs, 7), config(MillingMode::Down, 10_000.0));
    assert!(flags_in(&recs, 0).contains(Status::NOT_CUTTING));
    let entry = (1..=20).fold(Status::VALID, |a, k| a | flags_in(&recs, k));
    assert!(entry.contains(Status::TRANSIENT), "entry: {entry}");
    assert!(flags_in(&recs, 42).contains(Status::NOT_CUTTING));
    // Whatever is reported valid anywhere is right: 5 % of truth.
    let n = valid_ones_are_right(&recs, 0.05);
    assert!(n > 40, "steady part reported: {n}");
}

#[test]
fn axial_step_feed_step_and_speed_change_are_flagged() {
    let segs = vec![
        seg(2.0, 3.0, 6.0, 250.0),
        seg(2.0, 3.0, 11.0, 250.0), // axial step
        seg(2.0, 3.0, 11.0, 500.0), // feed doubles
        Seg {
            dur_s: 2.0,
            dr_mm: 3.0,
            da_mm: 11.0,
            feed_mm_min: 500.0,
            rpm: 660.0,
        }, // speed +10 %
    ];
    let recs = run(&paper(segs, 11), config(MillingMode::Down, 10_000.0));
    assert!(
        flags_in(&recs, 1).contains(Status::TRANSIENT),
        "{}",
        flags_in(&recs, 1)
    );
    assert!(
        flags_in(&recs, 2).contains(Status::FEED_CHANGE),
        "{}",
        flags_in(&recs, 2)
    );
    assert!(flags_in(&recs, 3).intersects(Status::FEED_CHANGE | Status::PERIOD_INVALID));
    // After each change the estimate comes back, and right.
    for k in 0..4 {
        let last = recs
            .iter()
            .rev()
            .find(|(_, t)| t.seg == k)
            .expect("records");
        assert!(
            last.0.status.is_valid(),
            "segment {k} ends {}",
            last.0.status
        );
    }
    valid_ones_are_right(&recs, 0.05);
}

#[test]
fn strong_runout_does_not_bias_the_estimate() {
    // One flute cutting 35 % more than the others (method.md: commercial monitors must
    // tolerate 30-40 %). The revolution means remove it.
    let mut sc = paper(vec![seg(3.0, 2.0, 11.0, 500.0)], 5);
    // Flute 0 sits 0.35 t_c further out: it cuts 1.35 t_c, the next flute 0.65 t_c.
    sc.runout_mm = [0.35 * 500.0 / 2400.0, 0.0, 0.0, 0.0];
    let recs = run(&sc, config(MillingMode::Down, 10_000.0));
    // Check the premise: tooth averages really are that uneven.
    let ft: Vec<f32> = recs.iter().skip(20).take(4).map(|(r, _)| r.f2_n).collect();
    let (lo, hi) = ft
        .iter()
        .fold((f32::MAX, 0.0f32), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(hi / lo > 1.2, "runout too weak to test: {ft:?}");
    assert!(valid_ones_are_right(&recs, 0.05) > 60);
}

#[test]
fn up_milling_and_one_pulse_per_revolution() {
    let mut sc = paper(vec![seg(3.0, 6.0, 6.0, 500.0)], 9);
    sc.mode = MillingMode::Up;
    // The generator pulses per tooth; keep only flute 0's pulses.
    let mut tooth = 0;
    let recs = run_with(&sc, config_per_rev(MillingMode::Up), |_, s| {
        if s.sync {
            s.sync = tooth % 4 == 0;
            tooth += 1;
        }
    });
    assert!(valid_ones_are_right(&recs, 0.05) > 60);
}

fn config_per_rev(mode: MillingMode) -> MonitorConfig {
    MonitorConfig {
        sync: SyncMode::PerRevolution,
        ..config(mode, 10_000.0)
    }
}

#[test]
fn bad_input_is_flagged_and_the_monitor_recovers() {
    let sc = paper(vec![seg(6.0, 3.0, 6.0, 250.0)], 13);
    let mut cfg = config(MillingMode::Down, 10_000.0);
    cfg.clip = [20.0, 20.0, 50.0];
    let mut pulse = 0usize;
    let recs = run_with(&sc, cfg, |i, s| {
        let t = i as f64 / 10_000.0;
        match t {
            t if (0.5..0.501).contains(&t) => s.feed[0] = f32::NAN,
            t if (1.0..1.001).contains(&t) => s.spindle = f32::INFINITY,
            t if (1.5..1.5005).contains(&t) => s.feed[0] = 25.0, // saturated ADC
            t if (2.5..2.7).contains(&t) => s.feed_velocity_mm_min = [0.0, 0.0], // feed hold
            t if (3.5..3.6).contains(&t) => s.feed_velocity_mm_min = [-250.0, 0.0], // reversing
            _ => {}
        }
        if s.sync {
            pulse += 1;
            // A lost pulse at 2.0 s, a doubled one at 4.0 s (half a tooth later).
            if (2.0..2.03).contains(&t) && pulse % 7 == 0 {
                s.sync = false;
            }
        }
        if (4.0125..4.0126).contains(&t) {
            s.sync = true;
        }
    });
    let at = |t0: f64, t1: f64| {
        recs.iter()
            .filter(|(r, _)| (t0..t1).contains(&r.time_s(10_000.0)))
            .fold(Status::VALID, |a, (r, _)| a | r.status)
    };
    assert!(
        at(0.5, 0.53).contains(Status::INPUT_FAULT),
        "NaN: {}",
        at(0.5, 0.53)
    );
    assert!(
        at(1.0, 1.03).contains(Status::INPUT_FAULT),
        "inf: {}",
        at(1.0, 1.03)
    );
    assert!(
        at(1.5, 1.53).contains(Status::INPUT_FAULT),
        "clip: {}",
        at(1.5, 1.53)
    );
    assert!(
        at(2.5, 2.73).contains(Status::NOT_CUTTING),
        "feed hold: {}",
        at(2.5, 2.73)
    );
    assert!(!at(3.5, 3.63).is_valid(), "reversing: {}", at(3.5, 3.63));
    assert!(
        at(4.0, 4.03).contains(Status::PERIOD_INVALID),
        "glitch: {}",
        at(4.0, 4.03)
    );
    // Recovery: the last second is reported, and right.
    assert!(at(5.2, 6.0).is_valid(), "{}", at(5.2, 6.0));
    valid_ones_are_right(&recs, 0.05);
}
