//! Synthetic cuts for the monitor tests: instantaneous forces from the closed-form
//! per-flute integrals of paper 000 eq. 4 (helical flute, coefficients at `t_a`), turned
//! into what the board sees (drive currents with lag and noise, encoder pulses).
//!
//! Independent of the code under test: it never calls eq. 7 or the tooth averager; the
//! per-tooth averages the monitor computes have to come out of the time signal.
#![allow(dead_code, clippy::unwrap_used)]

use estimator_core::drive::{FeedAxis, FeedDrive, SpindleModel};
use estimator_core::geometry::{average_chip_thickness_mm, engaged_arc_rad, entry_exit_rad};
use estimator_core::monitor::Input;
use estimator_core::table::{Segment, Segments};
use estimator_core::{
    CuttingCoefficients, EstimatorConfig, MillingMode, Monitor, MonitorConfig, MonitorState,
    Sample, Status, Tool, ToothRecord, TABLE2,
};
use std::f64::consts::PI;

/// Instantaneous total forces on the cutter `(F_t-sum, F_x, F_y)` [N] at rotation angle
/// `theta` of flute 0, for chip loads `tc_per_flute` (runout makes them unequal) and the
/// coefficients held at the nominal `t_a`.
#[allow(clippy::too_many_arguments)]
pub fn instantaneous(
    tool: &Tool,
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    rr: f64,
    ra: f64,
    tc_nominal: f64,
    tc_per_flute: &[f64],
    theta: f64,
) -> (f64, f64, f64) {
    let r = tool.radius_mm as f64;
    let tan_b = (tool.helix_deg as f64).to_radians().tan();
    let (st, ex) = entry_exit_rad(mode, rr as f32);
    let (st, ex) = (st as f64, ex as f64);
    let t_a = average_chip_thickness_mm(tc_nominal as f32, rr as f32, engaged_arc_rad(rr as f32));
    let ks = coeffs.ks.at(t_a) as f64;
    let r1 = coeffs.r1.at(t_a) as f64;
    let da = ra * r;
    let phi_a = da * tan_b / r;
    let n = tool.flutes as usize;
    let (mut ft, mut fx, mut fy) = (0.0, 0.0, 0.0);
    for j in 0..n {
        let tc = tc_per_flute.get(j).copied().unwrap_or(tc_nominal).max(0.0);
        // Flute j + 1 trails flute j by one pitch: it follows it into the cut and takes
        // the chip j leaves (runout, breakage).
        let phi = (theta - j as f64 * 2.0 * PI / n as f64).rem_euclid(2.0 * PI);
        if tan_b == 0.0 {
            if phi >= st && phi <= ex {
                let dft = ks * tc * phi.sin() * da;
                ft += dft;
                fx += dft * (phi.cos() + r1 * phi.sin());
                fy += dft * (-phi.sin() + r1 * phi.cos());
            }
            continue;
        }
        // Engaged heights map to angles [phi - phi_a, phi] (mod 2 pi); with phi in
        // [0, 2 pi) and the arc inside [0, pi], only shifts 0..=(phi_a + pi) / 2 pi meet it.
        let k = ks * tc * r / tan_b;
        let m_max = ((phi_a + PI) / (2.0 * PI)).ceil() as i64;
        for m in 0..=m_max {
            let hi = (phi + 2.0 * PI * m as f64).min(ex);
            let lo = (phi + 2.0 * PI * m as f64 - phi_a).max(st);
            if hi > lo {
                // Antiderivatives of sin, sin cos, sin^2.
                let c = lo.cos() - hi.cos();
                let a = 0.5 * (hi.sin().powi(2) - lo.sin().powi(2));
                let b = 0.5 * (hi - lo) - 0.25 * ((2.0 * hi).sin() - (2.0 * lo).sin());
                ft += k * c;
                fx += k * (a + r1 * b);
                fy += k * (-b + r1 * a);
            }
        }
    }
    (ft, fx, fy)
}

/// Deterministic xorshift + Box-Muller, so failures reproduce.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn gauss(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

/// A steady stretch of cutting (or air, with `dr_mm = 0`).
#[derive(Clone, Copy, Debug)]
pub struct Seg {
    pub dur_s: f64,
    pub dr_mm: f64,
    pub da_mm: f64,
    pub feed_mm_min: f64,
    pub rpm: f64,
}

pub struct Scenario {
    pub mode: MillingMode,
    pub fs: f64,
    pub segs: Vec<Seg>,
    /// Tooth-average force noise, relative to the tangential force.
    pub noise_rel: f64,
    /// Radial offset of each flute [mm] (runout).
    pub runout_mm: [f64; 4],
    /// First-order current-loop lag [s].
    pub lag_s: f64,
    pub seed: u64,
    /// `(time_s, flute, loss)`: from `time_s` on, `flute` cuts `1 - loss` of its chip and
    /// the next flute takes the rest (loss 1: the flute is gone).
    pub break_at: Option<(f64, usize, f64)>,
}

pub fn feed_axis() -> FeedAxis {
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

pub fn spindle() -> SpindleModel {
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

pub fn config(mode: MillingMode, fs: f64) -> MonitorConfig {
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
pub struct Truth {
    pub seg: usize,
    pub dr_mm: f64,
    pub da_mm: f64,
    /// Whether the break has happened at this sample.
    pub broken: bool,
}

/// Generates the scenario's samples and hands each (with its truth) to `f`.
pub fn generate(sc: &Scenario, mut f: impl FnMut(&Sample, Truth)) {
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
    let mut time = 0.0f64;
    for (k, seg) in sc.segs.iter().enumerate() {
        let tc = seg.feed_mm_min / (n as f64 * seg.rpm);
        // Runout: flute j cuts the chip left by flute j-1 plus the difference of offsets.
        let tcs: Vec<f64> = (0..n)
            .map(|j| tc + sc.runout_mm[j] - sc.runout_mm[(j + n - 1) % n])
            .collect();
        let tcs_broken: Vec<f64> = match sc.break_at {
            Some((_, b, loss)) => (0..n)
                .map(|j| {
                    if j == b {
                        tcs[j] * (1.0 - loss)
                    } else if j == (b + 1) % n {
                        tcs[j] + tcs[b] * loss
                    } else {
                        tcs[j]
                    }
                })
                .collect(),
            None => tcs.clone(),
        };
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
            time += dt;
            let broken = sc.break_at.is_some_and(|(t, _, _)| time >= t);
            let chips = if broken { &tcs_broken } else { &tcs };
            let (ft, fx, _fy) = if cutting {
                instantaneous(&tool, &TABLE2, sc.mode, rr, seg.da_mm / r, tc, chips, theta)
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
                    broken,
                },
            );
        }
    }
}

/// Runs the monitor over a scenario; returns records with the truth at their end.
pub fn run(sc: &Scenario, cfg: MonitorConfig) -> Vec<(ToothRecord, Truth)> {
    run_with(sc, cfg, |_, _| {})
}

/// Same, letting `tamper(sample_index, sample)` break the input first.
pub fn run_with(
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
pub fn paper(segs: Vec<Seg>, seed: u64) -> Scenario {
    Scenario {
        mode: MillingMode::Down,
        fs: 10_000.0,
        segs,
        noise_rel: 0.01,
        runout_mm: [0.01, 0.0, 0.0, 0.0],
        lag_s: 5e-4,
        seed,
        break_at: None,
    }
}

pub fn seg(dur_s: f64, dr_mm: f64, da_mm: f64, feed_mm_min: f64) -> Seg {
    Seg {
        dur_s,
        dr_mm,
        da_mm,
        feed_mm_min,
        rpm: 600.0,
    }
}

/// An engagement change as the cutter meets it: from `from` (depths, feed, speed) to `to`
/// over `travel_mm` of feed at `from`'s feed (a step in the part is entered over about a
/// tool radius of travel, not in an instant), in `steps` segments, the last at `to`.
pub fn travel(from: &Seg, to: &Seg, travel_mm: f64, steps: usize) -> Vec<Seg> {
    let dur = travel_mm / (from.feed_mm_min / 60.0) / steps as f64;
    (1..=steps)
        .map(|k| {
            let a = k as f64 / steps as f64;
            Seg {
                dur_s: dur,
                dr_mm: from.dr_mm + a * (to.dr_mm - from.dr_mm),
                da_mm: from.da_mm + a * (to.da_mm - from.da_mm),
                feed_mm_min: from.feed_mm_min + a * (to.feed_mm_min - from.feed_mm_min),
                rpm: from.rpm + a * (to.rpm - from.rpm),
            }
        })
        .collect()
}

/// Every record reported valid is within `tol` of the truth; returns how many were valid.
/// "The truth" of a filtered estimate is whatever the cut was over the filter window (the
/// last 16 teeth): the estimate must lie within `tol` of that range.
pub fn valid_ones_are_right(recs: &[(ToothRecord, Truth)], tol: f64) -> usize {
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
pub fn flags_in(recs: &[(ToothRecord, Truth)], k: usize) -> Status {
    recs.iter()
        .filter(|(_, t)| t.seg == k)
        .fold(Status::VALID, |a, (r, _)| a | r.status)
}
