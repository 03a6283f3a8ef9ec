//! The voxel simulator's raw trace (`voxel::trace`): a straight cut through the board's
//! models, read back by the trace reader and replayed through the Monitor, against eq. 7
//! and the analytic simulator; the frames (feed along X and Y, signs of light down milling);
//! `host-sim voxel --output` and `--board` end to end.

#![allow(clippy::unwrap_used)]

mod voxel_common;

use estimator_core::coefficients::{CuttingCoefficients, LinearCoefficients, PowerLaw, AL6061};
use estimator_core::monitor::Input;
use estimator_core::{
    EstimatorConfig, MillingMode, MonitorConfig, Solver, Status, Tool, ToothRecord,
};
use host_sim::replay;
use host_sim::sim::{simulate, Scenario};
use host_sim::trace::{FeedSignal, SpindleSignal, TraceReader, TraceRow, TraceWriter, Truth};
use host_sim::voxel::sim::run_path;
use host_sim::voxel::trace::{BoardSpec, TraceSampler, TraceSummary};
use host_sim::voxel::{run, VoxelArgs};
use std::path::PathBuf;
use voxel_common::*;
use MillingMode::{Down, Up};

const FS: f64 = 20_000.0;

/// A motor board with non-trivial drive models: friction, offsets, a negative axis sign,
/// an idle spindle current rising with speed (the constants of tests/simulate.rs).
const MOTOR_BOARD: &str = r#"
[input.motor.feed]
two_axis = TWO_AXIS
[[input.motor.feed.axes]]
torque_constant_nm_per_a = 1.2
screw_lead_mm = 10.0
efficiency = 0.9
current_offset_a = 0.05
coulomb_n = 40.0
viscous_n_per_mm_min = 0.02
stiction_band_mm_min = 1.0
sign = -1.0
[[input.motor.feed.axes]]
torque_constant_nm_per_a = 1.2
screw_lead_mm = 10.0
efficiency = 0.9
current_offset_a = 0.05
coulomb_n = 40.0
viscous_n_per_mm_min = 0.02
stiction_band_mm_min = 1.0
sign = 1.0
[input.motor.spindle.current]
torque_constant_nm_per_a = 0.8
[[input.motor.spindle.current.idle_current_a]]
from_rpm = 0.0
slope = 0.0001
intercept = 0.5
"#;

fn motor_board(two_axis: bool) -> BoardSpec {
    let text = MOTOR_BOARD.replace("TWO_AXIS", if two_axis { "true" } else { "false" });
    BoardSpec::from_toml(&text, "MOTOR_BOARD").unwrap()
}

fn dyno_board() -> BoardSpec {
    BoardSpec::from_toml("input = \"dynamometer\"\n", "DYNO").unwrap()
}

/// A straight cut long enough for the Monitor's filter: 30 mm of block, the tool stopping
/// at 24 mm.
fn long_cut(mode: MillingMode, dr: f64, tc: f64) -> Cut {
    Cut {
        stock_len: 30.0,
        end: 24.0,
        ..Cut::new(mode, dr, 2.7, tc, 0.09)
    }
}

/// The cut through `board` as raw trace text, and the sampler's counters.
fn trace(c: &Cut, board: &BoardSpec) -> (Vec<u8>, TraceSummary) {
    let (mut sim, path) = setup(c);
    let cutter = sim.config().cutter.clone();
    let mut tw = TraceWriter::new(Vec::new(), board.trace_kind(), FS).unwrap();
    let mut sampler = TraceSampler::new(board, &cutter, FS, path.t_start);
    run_path(&mut sim, &path, |s| sampler.step(s, |r| tw.write_row(r))).unwrap();
    (tw.finish().unwrap(), sampler.summary())
}

fn rows(bytes: &[u8]) -> Vec<TraceRow> {
    let mut rd = TraceReader::new(bytes, "voxel trace").unwrap();
    let mut out = Vec::new();
    while let Some(r) = rd.next_row().unwrap() {
        out.push(r);
    }
    out
}

/// The Monitor of the cut's tool on `board`'s input at `FS`.
fn monitor_config(c: &Cut, board: &BoardSpec) -> MonitorConfig {
    MonitorConfig {
        sample_rate_hz: FS as f32,
        input: board.input.clone(),
        estimator: EstimatorConfig {
            tool: Tool {
                radius_mm: R as f32,
                flutes: FLUTES,
                helix_deg: c.helix as f32,
            },
            mode: c.mode,
            ..EstimatorConfig::default()
        },
        ..MonitorConfig::default()
    }
}

fn replay_trace(bytes: &[u8], cfg: &MonitorConfig) -> Vec<(ToothRecord, Truth)> {
    let mut rd = TraceReader::new(bytes, "voxel trace").unwrap();
    let mut recs = Vec::new();
    replay::replay(&mut rd, cfg, |r, t| recs.push((*r, *t))).unwrap();
    recs
}

/// Feed speed of the cut [mm/s].
fn speed(c: &Cut) -> f64 {
    c.tc * f64::from(FLUTES) * RPM / 60.0
}

/// Records whose whole tooth period has the tool centre in the steady part of the cut
/// (past 1 mm into the block, 1 mm before the stop).
fn steady(c: &Cut, recs: &[(ToothRecord, Truth)]) -> Vec<(ToothRecord, Truth)> {
    let v = speed(c);
    recs.iter()
        .filter(|(r, _)| {
            let t_end = r.end_sample as f64 / FS;
            let t_start = t_end - f64::from(r.samples) / FS;
            let along = |t: f64| -R - 0.5 + v * t;
            along(t_start) >= 1.0 && along(t_end) <= c.end - 1.0
        })
        .copied()
        .collect()
}

/// Input-side flags: none may be set on a steady record of a clean trace.
const INPUT_FLAGS: Status = Status::NON_FINITE
    .with(Status::PERIOD_INVALID)
    .with(Status::NO_SYNC)
    .with(Status::INPUT_FAULT);

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    s / n as f64
}

/// Replays the cut's trace and compares the steady tooth averages (`fx_n`, `f2_n`) with
/// eq. 7 for the programmed cut: the mean within 5 % of `|F_at|` (components pass through
/// zero, the tangential force does not; as tests/voxel_forces.rs). Returns the errors.
/// (Single tooth periods scatter by up to 20 % at light immersion, where a chip is a
/// fraction of a voxel: only the mean is checked.)
fn check_replayed_forces(c: &Cut, board: &BoardSpec) -> [f64; 2] {
    let (bytes, summary) = trace(c, board);
    let recs = replay_trace(&bytes, &monitor_config(c, board));
    let steady = steady(c, &recs);
    assert!(steady.len() > 150, "{} steady records", steady.len());
    for (r, _) in &steady {
        assert!(
            !r.status.intersects(INPUT_FLAGS),
            "record at {} s: {}",
            r.end_sample as f64 / FS,
            r.status
        );
        assert!(
            (66..=67).contains(&r.samples),
            "tooth period of 1/300 s at 20 kHz is 66.7 samples, not {}",
            r.samples
        );
    }
    let a = analytic(c);
    let second = match board.input {
        Input::Dynamometer => a.fy_n,
        Input::Motor { .. } => a.ft_n,
    };
    let want = [f64::from(a.fx_n), f64::from(second)];
    let scale = f64::from(a.ft_n).abs();
    let got = [
        mean(steady.iter().map(|(r, _)| f64::from(r.fx_n))),
        mean(steady.iter().map(|(r, _)| f64::from(r.f2_n))),
    ];
    let err = [(got[0] - want[0]) / scale, (got[1] - want[1]) / scale];
    eprintln!(
        "{:?} dr {} tc {}: replayed [{:.2}, {:.2}] N, eq. 7 [{:.2}, {:.2}] N: {:+.2} %, {:+.2} % \
         of F_at; {} rows, {} sync pulses",
        c.mode,
        c.dr,
        c.tc,
        got[0],
        got[1],
        want[0],
        want[1],
        100.0 * err[0],
        100.0 * err[1],
        summary.rows,
        summary.sync_pulses
    );
    for e in err {
        assert!(e.abs() < 0.05, "{err:?}");
    }
    err
}

#[test]
fn replayed_motor_currents_give_the_eq7_forces() {
    // Motor route: F_ax from the feed current through the drive model (negative axis sign,
    // friction, offset), F_at from the spindle current over its idle.
    check_replayed_forces(&long_cut(Down, 2.5, 0.1), &motor_board(false));
    check_replayed_forces(&long_cut(Down, 1.0, 0.05), &motor_board(false));
}

#[test]
fn replayed_dynamometer_forces_give_the_eq7_forces() {
    check_replayed_forces(&long_cut(Up, 2.5, 0.1), &dyno_board());
    check_replayed_forces(&long_cut(Down, 10.0, 0.05), &dyno_board());
}

#[test]
fn replay_estimates_the_programmed_engagement() {
    // A material the estimator's power laws describe exactly: Al6061's shearing
    // coefficients without edge forces are power laws with exponent 0 (K_s = K_tc,
    // r1 = K_rc / K_tc, r2 = K_ac / K_tc). The exact inversion then has no coefficient
    // mismatch, and the estimates test the whole path: voxels, board, trace, Monitor. What
    // remains is the voxel forces' 1-2 % departure from eq. 7 (docs/voxel.md), which the
    // inversion amplifies to 3-5 % in d_r and d_a at R_r 0.5 down milling: the mean within
    // 5 %, each record within 6 %.
    let lin = LinearCoefficients {
        kte: 0.0,
        kre: 0.0,
        kae: 0.0,
        ..AL6061
    };
    let law = |k: f32| PowerLaw { k, p: 0.0 };
    let coeffs = CuttingCoefficients {
        ks: law(lin.ktc),
        r1: law(lin.krc / lin.ktc),
        r2: law(lin.kac / lin.ktc),
        tc_fit_mm: (0.01, 0.5),
    };
    let board = motor_board(false);
    for (mode, dr) in [(Down, 2.5), (Down, 5.0), (Up, 4.0), (Down, 10.0)] {
        let c = Cut {
            coeffs: lin,
            ..long_cut(mode, dr, 0.1)
        };
        let (bytes, _) = trace(&c, &board);
        let mut cfg = monitor_config(&c, &board);
        cfg.estimator.coeffs = coeffs;
        cfg.estimator.solver = Solver::Inversion;
        let recs = replay_trace(&bytes, &cfg);
        let valid: Vec<_> = steady(&c, &recs)
            .into_iter()
            .filter(|(r, _)| r.status.is_valid())
            .collect();
        assert!(valid.len() > 100, "{mode:?}: {} valid records", valid.len());
        let err = |(r, _): &(ToothRecord, Truth)| {
            (
                (f64::from(r.dr_mm) - dr) / dr,
                (f64::from(r.da_mm) - c.da) / c.da,
            )
        };
        let (e_r, e_a) = (
            mean(valid.iter().map(|v| err(v).0)),
            mean(valid.iter().map(|v| err(v).1)),
        );
        eprintln!(
            "{mode:?} d_r {dr}: {} valid records, d_r {:+.2} %, d_a {:+.2} % (mean)",
            valid.len(),
            100.0 * e_r,
            100.0 * e_a
        );
        assert!(e_r.abs() < 0.05 && e_a.abs() < 0.05, "{e_r} {e_a}");
        for v in &valid {
            let (e_r, e_a) = err(v);
            assert!(
                e_r.abs() < 0.06 && e_a.abs() < 0.06,
                "{mode:?} at {} s: d_r {} d_a {}",
                v.0.end_sample as f64 / FS,
                v.0.dr_mm,
                v.0.da_mm
            );
        }
    }
}

/// Steady rows (tool centre 1 mm into the block to 1 mm before the stop).
fn steady_rows(c: &Cut, rows: &[TraceRow]) -> Vec<TraceRow> {
    let v = speed(c);
    rows.iter()
        .filter(|r| {
            let a = -R - 0.5 + v * r.time_s;
            a >= 1.0 && a <= c.end - 1.0
        })
        .copied()
        .collect()
}

/// The analytic simulator's dynamometer trace of the same cut (Al6061, tool, speeds).
fn analytic_trace(c: &Cut) -> Vec<TraceRow> {
    let duration = (c.end + R + 0.5) / speed(c);
    let text = format!(
        r#"
sample_rate_hz = {FS}
input = "dynamometer"
material = "al6061"
mode = "{mode}"
[tool]
radius_mm = {R}
flutes = {FLUTES}
helix_deg = {helix}
[[segment]]
duration_s = {duration}
rpm = {RPM}
feed_mm_min = {feed}
dr_mm = {dr}
da_mm = {da}
"#,
        mode = if c.mode == Down { "down" } else { "up" },
        helix = c.helix,
        feed = speed(c) * 60.0,
        dr = c.dr,
        da = c.da,
    );
    let sc = Scenario::from_toml(&text, "analytic").unwrap();
    let mut out = Vec::new();
    simulate(&sc, |r| {
        out.push(*r);
        Ok(())
    })
    .unwrap();
    out
}

#[test]
fn light_down_milling_pulls_the_work_as_in_the_analytic_simulator() {
    // R_r 0.2 down milling along +X: F_ax < 0 (the cutter pulls the work along the feed),
    // in the voxel trace's truth as in the analytic simulator's, and in the dynamometer
    // channel itself; F_ay, F_at agree too.
    let c = long_cut(Down, 1.0, 0.1);
    let (bytes, _) = trace(&c, &dyno_board());
    let vox = steady_rows(&c, &rows(&bytes));
    let ana_all = analytic_trace(&c);
    let ana: Vec<TraceRow> = ana_all
        .iter()
        .filter(|r| r.time_s > 6.5 / speed(&c))
        .copied()
        .collect();
    let m = |rows: &[TraceRow], f: fn(&TraceRow) -> f32| mean(rows.iter().map(|r| f64::from(f(r))));
    let v = [
        m(&vox, |r| r.truth.fx_n),
        m(&vox, |r| r.truth.fy_n),
        m(&vox, |r| r.truth.ft_n),
    ];
    let a = [
        m(&ana, |r| r.truth.fx_n),
        m(&ana, |r| r.truth.fy_n),
        m(&ana, |r| r.truth.ft_n),
    ];
    eprintln!("voxel truth {v:.2?} N, analytic truth {a:.2?} N");
    assert!(
        v[0] < 0.0 && a[0] < 0.0,
        "F_ax: voxel {} analytic {}",
        v[0],
        a[0]
    );
    assert!(v[2] > 0.0 && a[2] > 0.0);
    for k in 0..3 {
        assert!(
            (v[k] - a[k]).abs() < 0.06 * a[2],
            "component {k}: voxel {} analytic {}",
            v[k],
            a[k]
        );
    }
    // The dynamometer channels carry the same forces (ideal chain).
    assert_eq!(m(&vox, |r| r.feed[0]), v[0]);
    assert_eq!(m(&vox, |r| r.feed[1]), v[1]);
    // Up milling the same cut pushes the work back (F_ax > 0).
    let c = long_cut(Up, 1.0, 0.1);
    let up = steady_rows(&c, &rows(&trace(&c, &dyno_board()).0));
    assert!(m(&up, |r| r.truth.fx_n) > 0.0);
}

#[test]
fn feed_along_y_gives_the_same_feed_frame_forces() {
    // The same cut fed along +Y through a two-axis drive: the same feed-frame truth, and a
    // replay through the two-axis inverse gives the same tooth forces.
    let board = motor_board(true);
    let cx = long_cut(Down, 2.5, 0.1);
    let cy = Cut {
        feed: Feed::PlusY,
        ..cx
    };
    let mut means = Vec::new();
    for c in [&cx, &cy] {
        let (bytes, _) = trace(c, &board);
        let rs = steady_rows(c, &rows(&bytes));
        let truth = [
            mean(rs.iter().map(|r| f64::from(r.truth.fx_n))),
            mean(rs.iter().map(|r| f64::from(r.truth.fy_n))),
            mean(rs.iter().map(|r| f64::from(r.truth.ft_n))),
        ];
        let recs = steady(c, &replay_trace(&bytes, &monitor_config(c, &board)));
        let replayed = [
            mean(recs.iter().map(|(r, _)| f64::from(r.fx_n))),
            mean(recs.iter().map(|(r, _)| f64::from(r.f2_n))),
        ];
        // Replay inverts the board exactly (up to f32 and the tooth windows).
        assert!(
            (replayed[0] - truth[0]).abs() < 0.01 * truth[2],
            "{replayed:?} {truth:?}"
        );
        assert!(
            (replayed[1] - truth[2]).abs() < 0.01 * truth[2],
            "{replayed:?} {truth:?}"
        );
        means.push(truth);
    }
    eprintln!("+X {:.2?}, +Y {:.2?}", means[0], means[1]);
    for k in 0..3 {
        assert!(
            (means[0][k] - means[1][k]).abs() < 0.02 * means[0][2],
            "component {k}: +X {} +Y {}",
            means[0][k],
            means[1][k]
        );
    }
}

/// A scratch directory of this test process.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voxel-trace-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn voxel_command_writes_a_raw_trace_through_the_board() {
    let d = scratch("cli");
    // A 2 mm deep, 2.5 mm wide down-milling side cut along +X, 6000 rpm, 0.05 mm/tooth:
    // 1.2 s.
    let nc = d.join("cut.nc");
    std::fs::write(&nc, "G21 G90\nS6000 M3\nG1 X12 F900\n").unwrap();
    let board = d.join("board.toml");
    std::fs::write(
        &board,
        "sync = \"per_revolution\"\nseed = 3\n[signal]\nfeed_noise = 0.01\nadc_bits = 16\n\
         feed_full_scale = 20.0\nspindle_full_scale = 50.0\n",
    )
    .unwrap();
    let (out, steps) = (d.join("trace.csv"), d.join("steps.csv"));
    let args = VoxelArgs {
        stock: "0,-8,-3,16,-2.5,0".into(),
        voxel_mm: 0.15,
        tool: "radius=5,flutes=3,helix=30,length=10".into(),
        toolpath: nc.clone(),
        output: Some(out.clone()),
        board: Some(board.clone()),
        steps_csv: Some(steps.clone()),
        start: Some("-6,0,-2".into()),
        ..VoxelArgs::default()
    };
    run(&args).unwrap();
    let bytes = std::fs::read(&out).unwrap();
    let rd = TraceReader::new(&bytes[..], "trace.csv").unwrap();
    let k = rd.kind();
    assert_eq!(k.feed, FeedSignal::Current);
    assert!(!k.two_axis && k.has_velocity && k.has_truth);
    assert_eq!(k.spindle, SpindleSignal::Current);
    assert_eq!(rd.sample_rate_hz(), Some(FS));
    let rs = rows(&bytes);
    assert_eq!(rs.len(), 24_000, "1.2 s at 20 kHz");
    // One pulse per revolution: 120 revolutions, the first at the start.
    assert_eq!(rs.iter().filter(|r| r.sync).count(), 120);
    assert!(rs.iter().all(|r| r.feed_velocity_mm_min[0] == 900.0));
    // Fully engaged from x = 3 mm (0.6 s) until the tool's front leaves the block at
    // x = 11 mm (1.13 s).
    let cutting: Vec<_> = rs
        .iter()
        .filter(|r| r.time_s > 0.6 && r.time_s < 1.1)
        .collect();
    assert!(cutting.iter().all(|r| r.truth.rpm == 6000.0
        && r.truth.flutes_intact == 7
        && (r.truth.tc_mm - 0.05).abs() < 1e-6));
    assert!(cutting
        .iter()
        .all(|r| (r.truth.da_mm - 2.0).abs() <= 0.15 + 1e-6));
    assert!(cutting
        .iter()
        .all(|r| (r.truth.dr_mm - 2.5).abs() <= 0.15 + 1e-6));
    // 16-bit codes of 20 A full scale; the noise makes them differ.
    let lsb = 20.0 / 32768.0;
    assert!(cutting
        .iter()
        .all(|r| ((r.feed[0] as f64 / lsb) - (r.feed[0] as f64 / lsb).round()).abs() < 1e-3));
    // The step CSV: one row per step with the removal rate.
    let text = std::fs::read_to_string(&steps).unwrap();
    assert_eq!(text.lines().count(), 1 + 2880);
    assert!(text
        .lines()
        .next()
        .unwrap()
        .ends_with("mrr_mm3_s,flutes_intact"));

    // Board errors name the file and the key or line.
    std::fs::write(&board, "[signal]\nadc_bits = 12\n").unwrap();
    let e = format!("{:#}", run(&args).unwrap_err());
    assert!(
        e.contains("board.toml") && e.contains("signal.feed_full_scale"),
        "{e}"
    );
    std::fs::write(&board, "[signal]\nfeed_nose = 1.0\n").unwrap();
    let e = format!("{:#}", run(&args).unwrap_err());
    assert!(
        e.contains("board.toml line 2") && e.contains("feed_nose"),
        "{e}"
    );
    let mut bad = args.clone();
    bad.board = None;
    bad.sample_rate_hz = 0.0;
    let e = format!("{:#}", run(&bad).unwrap_err());
    assert!(e.contains("--sample-rate-hz"), "{e}");
    // A failed run leaves no partial trace.
    assert!(!d.join("trace.csv.partial").exists());
    std::fs::remove_dir_all(&d).ok();
}
