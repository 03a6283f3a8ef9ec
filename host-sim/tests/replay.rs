//! Replay: a synthetic trace through the Monitor recovers the engagement it was made from;
//! the machine file; the records CSV; `--bits`; the plot; the command line end to end.

use estimator_core::drive::{FeedDrive, SpindleModel};
use estimator_core::monitor::{FeedVelocity, Input};
use estimator_core::{
    average_forces, Engagement, FrontEnd, MachineConfig, MillingMode, MonitorConfig, PipelineState,
    Status, Tool, ToothRecord, TABLE2,
};
use host_sim::evaluate::{draw_case, Kind};
use host_sim::plot::{self, PlotFormat};
use host_sim::records::{RecordReader, RecordWriter};
use host_sim::replay::{
    self, bits_line, parse_monitor_config, replay_to, RecordFormat, ReplayOutputs, MACHINE_EXAMPLE,
};
use host_sim::trace::{
    FeedSignal, SpindleSignal, TraceKind, TraceReader, TraceRow, TraceWriter, Truth,
};
use std::io::Cursor;
use std::path::PathBuf;

const RATE: f64 = 20_000.0;
const RPM: f32 = 600.0;
const DR_MM: f32 = 4.0;
const DA_MM: f32 = 6.0;
const TC_MM: f32 = 0.2;

/// A steady cut in the motor route: the forward model's tooth averages (eq. 7) turned into
/// constant currents by the drive models' inverses, one sync pulse per tooth period.
/// Velocity columns iff `with_velocity`; truth columns always.
fn synthetic_trace(seconds: f64, with_velocity: bool) -> Vec<u8> {
    let tool = Tool::PAPER;
    let r = tool.radius_mm;
    let f = average_forces(
        &tool,
        &TABLE2,
        MillingMode::Down,
        Engagement {
            rr: DR_MM / r,
            ra: DA_MM / r,
            tc_mm: TC_MM,
        },
    );
    let feed = FeedDrive::default();
    let spindle = SpindleModel::default();
    let v = [TC_MM * tool.flutes as f32 * RPM, 0.0];
    let i_feed = feed.currents_for_loads_a([f.fx_n, 0.0], v);
    let i_spindle = spindle.signal_for_force(f.ft_n, RPM, r);
    let period = (RATE * 60.0 / (f64::from(RPM) * f64::from(tool.flutes))).round() as u64;
    assert_eq!(period, 500);
    let kind = TraceKind {
        feed: FeedSignal::Current,
        two_axis: false,
        has_velocity: with_velocity,
        spindle: SpindleSignal::Current,
        has_truth: true,
    };
    let mut w = TraceWriter::new(Vec::new(), kind, RATE).expect("writer");
    let n = (seconds * RATE) as u64;
    for k in 0..n {
        w.write_row(&TraceRow {
            time_s: k as f64 / RATE,
            sync: k % period == 0,
            feed: [i_feed[0], 0.0],
            feed_velocity_mm_min: v,
            spindle: i_spindle,
            truth: Truth {
                dr_mm: DR_MM,
                da_mm: DA_MM,
                tc_mm: TC_MM,
                rpm: RPM,
                flutes_intact: 0xf,
                fx_n: f.fx_n,
                fy_n: f.fy_n,
                ft_n: f.ft_n,
            },
        })
        .expect("row");
    }
    w.finish().expect("finish")
}

fn reader(bytes: &[u8]) -> TraceReader<Cursor<&[u8]>> {
    TraceReader::new(Cursor::new(bytes), "synthetic.csv").expect("header")
}

fn config_for(bytes: &[u8], text: &str) -> MonitorConfig {
    let mut rd = reader(bytes);
    let rate = rd.detect_sample_rate_hz().expect("rate");
    parse_monitor_config(text, "test.toml", rate)
        .expect("config")
        .config
}

#[test]
fn synthetic_cut_recovers_the_depths_within_2_percent() {
    let trace = synthetic_trace(2.0, true);
    let cfg = config_for(&trace, "");
    assert_eq!(cfg.sample_rate_hz, 20_000.0, "taken from the trace");
    let mut records: Vec<(ToothRecord, Truth)> = Vec::new();
    let summary =
        replay::replay(&mut reader(&trace), &cfg, |r, t| records.push((*r, *t))).expect("replays");
    // 2 s at 600 rpm, 4 flutes: 80 tooth periods, the first pulse opens the first one.
    assert_eq!(summary.samples, 40_000);
    assert_eq!(summary.records, 79);
    assert_eq!(records.len(), 79);
    let valid: Vec<_> = records
        .iter()
        .filter(|(r, _)| r.status.is_valid())
        .collect();
    // Everything after the settling window (4 revolutions) is valid.
    assert!(valid.len() >= 79 - 16, "{} valid", valid.len());
    for (r, t) in &valid {
        assert_eq!(t.dr_mm, DR_MM);
        let e_dr = (r.dr_mm - DR_MM).abs() / DR_MM;
        let e_da = (r.da_mm - DA_MM).abs() / DA_MM;
        assert!(
            e_dr < 0.02 && e_da < 0.02,
            "d_r {} d_a {}",
            r.dr_mm,
            r.da_mm
        );
        assert!((r.rpm - RPM).abs() < 1e-3 && (r.tc_mm - TC_MM).abs() < 1e-5);
    }
    let e = summary.errors.expect("truth columns give statistics");
    assert_eq!(e.dr.count, valid.len() as u64);
    assert!(e.dr.max < 0.02 && e.da.max < 0.02, "{e:?}");
    assert_eq!(summary.valid, valid.len() as u64);
    let settling = Status::NAMES
        .iter()
        .position(|(s, _)| *s == Status::SETTLING)
        .expect("flag");
    assert_eq!(summary.flags[settling], 79 - summary.valid);
    assert!(summary
        .report("x")
        .contains("d_r vs the window-mean truth over"));
}

#[test]
fn nominal_feed_replaces_missing_velocity_columns() {
    let trace = synthetic_trace(1.0, false);
    let cfg = config_for(&trace, "");
    let e = replay::replay(&mut reader(&trace), &cfg, |_, _| {}).expect_err("no velocity");
    let msg = format!("{e:#}");
    assert!(
        msg.contains("no feed velocity columns") && msg.contains("nominal"),
        "{msg}"
    );
    let cfg = config_for(&trace, "feed_velocity = { nominal = [480.0, 0.0] }\n");
    assert_eq!(cfg.feed_velocity, FeedVelocity::Nominal([480.0, 0.0]));
    let mut valid = 0;
    replay::replay(&mut reader(&trace), &cfg, |r, _| {
        if r.status.is_valid() {
            valid += 1;
            assert!((r.dr_mm - DR_MM).abs() < 0.02 * DR_MM, "{}", r.dr_mm);
        }
    })
    .expect("replays");
    assert!(valid > 0);
}

#[test]
fn config_and_trace_must_agree() {
    let trace = synthetic_trace(0.1, true);
    let mut rd = reader(&trace);
    let rate = rd.detect_sample_rate_hz().expect("rate");
    let e = parse_monitor_config("sample_rate_hz = 10000.0\n", "m.toml", rate).expect_err("rate");
    let msg = format!("{e:#}");
    assert!(
        msg.starts_with("m.toml: sample_rate_hz = 10000") && msg.contains("20000"),
        "{msg}"
    );
    // The library API checks too.
    let mut cfg = config_for(&trace, "");
    cfg.sample_rate_hz = 10_000.0;
    let e = replay::replay(&mut reader(&trace), &cfg, |_, _| {}).expect_err("rate");
    assert!(format!("{e:#}").contains("sampled at 20000 Hz"));
    // Dynamometer config on a current trace.
    let cfg = config_for(&trace, "input = \"dynamometer\"\n");
    let e = replay::replay(&mut reader(&trace), &cfg, |_, _| {}).expect_err("input");
    assert!(format!("{e:#}").contains("dynamometer"));
    // A config error is the core's message.
    let cfg = config_for(&trace, "filter_revs = 0\n");
    let e = replay::replay(&mut reader(&trace), &cfg, |_, _| {}).expect_err("bad config");
    assert!(
        format!("{e:#}").contains("`filter_revs` is out of range"),
        "{e:#}"
    );
}

#[test]
fn machine_file_example_parses_and_builds() {
    let loaded = parse_monitor_config(MACHINE_EXAMPLE, "machine.toml", Some(20_000.0))
        .expect("example parses");
    let cfg = &loaded.config;
    cfg.clone().build().expect("example builds");
    assert_eq!(cfg.sample_rate_hz, 20_000.0);
    assert_eq!(cfg.clip, [9.5, 9.5, 19.5]);
    assert_eq!(cfg.estimator.gain_uncertainty, 0.02);
    let Input::Motor { feed, spindle } = &cfg.input else {
        panic!("motor input");
    };
    assert_eq!(feed.axes[0].coulomb_n, 40.0);
    assert_eq!(feed.axes[1].sign, -1.0);
    assert!(matches!(
        spindle,
        SpindleModel::Current { torque_constant_nm_per_a, .. } if *torque_constant_nm_per_a == 0.5
    ));
    assert!(loaded.sets(&["estimator", "tool", "flutes"]));
    assert!(!loaded.sets(&["sample_rate_hz"]));
    // The front end: given tables over the defaults, the rest default.
    let fe = &loaded.front_end;
    assert_eq!(fe.feed.units_per_volt, 2.0);
    assert_eq!(fe.feed_encoder.counts_per_mm, 2000.0);
    assert_eq!(fe.feed_encoder.window_blocks, 32);
    assert_eq!(fe.spindle, estimator_core::FrontEnd::default().spindle);
    // The committed file is the one the docs show.
    let docs = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/formats.md"),
    )
    .expect("docs/formats.md");
    assert!(
        docs.contains(MACHINE_EXAMPLE),
        "docs/formats.md must show host-sim/examples/machine.toml verbatim"
    );
}

#[test]
fn machine_file_front_end_is_optional_and_checked() {
    let d = parse_monitor_config("filter_revs = 3\n", "m.toml", Some(1e4)).expect("parses");
    assert_eq!(d.front_end, estimator_core::FrontEnd::default());
    let l = parse_monitor_config(
        "filter_revs = 3\n[front_end.spindle]\nunits_per_volt = 4.0\n",
        "m.toml",
        Some(1e4),
    )
    .expect("parses");
    assert_eq!(l.front_end.spindle.units_per_volt, 4.0);
    assert_eq!(l.front_end.spindle.front_end_gain, 0.15);
    assert_eq!(l.config.filter_revs, 3);
    let e = parse_monitor_config(
        "[front_end.feed]\nunits_per_volt = 0.0\n",
        "m.toml",
        Some(1e4),
    )
    .expect_err("zero scaling");
    assert!(
        format!("{e:#}").contains("front_end.feed.units_per_volt"),
        "{e:#}"
    );
    let e = parse_monitor_config("[front_end.feed]\ngain = 0.2\n", "m.toml", Some(1e4))
        .expect_err("typo");
    assert!(format!("{e:#}").contains("unknown key"), "{e:#}");
}

#[test]
fn machine_file_errors_and_overlay() {
    let e = parse_monitor_config("[estimator.tool]\nradius = 6.0\n", "m.toml", Some(1e4))
        .expect_err("typo");
    let msg = format!("{e:#}");
    assert!(
        msg.starts_with("m.toml: unknown key `estimator.tool.radius`"),
        "{msg}"
    );
    let e = parse_monitor_config("filter_rev = 3\n", "m.toml", Some(1e4)).expect_err("typo");
    assert!(format!("{e:#}").contains("unknown key `filter_rev`"));
    // Partial: the rest keeps its default.
    let cfg = parse_monitor_config("[estimator.tool]\nflutes = 2\n", "m.toml", Some(1e4))
        .expect("parses")
        .config;
    let d = MonitorConfig::default();
    assert_eq!(cfg.estimator.tool.flutes, 2);
    assert_eq!(cfg.estimator.tool.radius_mm, d.estimator.tool.radius_mm);
    assert_eq!(cfg.input, d.input);
    // Switching the spindle model to load starts from paper 003's.
    let cfg = parse_monitor_config(
        "[input.motor.spindle.load]\nswitch_rpm = 4000.0\n",
        "m.toml",
        Some(1e4),
    )
    .expect("parses")
    .config;
    let Input::Motor { spindle, .. } = &cfg.input else {
        panic!("motor");
    };
    let SpindleModel::Load { switch_rpm, .. } = spindle else {
        panic!("load model");
    };
    assert_eq!(*switch_rpm, 4000.0);
    // Without a rate from the trace, the file must give one.
    let e = parse_monitor_config("", "m.toml", None).expect_err("no rate");
    assert!(format!("{e:#}").contains("set sample_rate_hz"));
}

#[test]
fn records_csv_round_trips() {
    let trace = synthetic_trace(1.0, true);
    let cfg = config_for(&trace, "");
    let mut want: Vec<(f64, ToothRecord, Truth)> = Vec::new();
    let (summary, _, _) = replay_to(
        &mut reader(&trace),
        &cfg,
        Vec::new(),
        RecordFormat::Csv,
        &ReplayOutputs::default(),
        None,
    )
    .expect("replays");
    let mut out = Vec::new();
    replay::replay_source(&mut reader(&trace), &cfg, &Default::default(), None, |e| {
        want.push((e.time_s, *e.record, *e.truth));
        Ok(())
    })
    .expect("replays");
    {
        let mut w = RecordWriter::new(&mut out, true).expect("header");
        for (t, r, truth) in &want {
            w.write(*t, r, truth).expect("row");
        }
        w.finish().expect("finish");
    }
    assert_eq!(summary.records as usize, want.len());
    let mut rd = RecordReader::new(Cursor::new(&out), "records.csv").expect("header");
    assert!(rd.has_truth());
    for (t, r, truth) in &want {
        let got = rd.next_row().expect("row").expect("not at the end");
        assert_eq!(got.time_s.to_bits(), t.to_bits());
        // Every word but end_sample, which the file keeps as time_s.
        assert_eq!(got.record.to_words()[2..], r.to_words()[2..]);
        let gt = got.truth.expect("truth");
        assert_eq!(
            (gt.dr_mm, gt.da_mm, gt.tc_mm),
            (truth.dr_mm, truth.da_mm, truth.tc_mm)
        );
    }
    assert!(rd.next_row().expect("end").is_none());
    // The header is the documented one.
    let text = String::from_utf8(out).expect("utf8");
    assert!(text.starts_with(
        "time_s,tooth,samples,rpm,tc_mm,fx_n,f2_n,fx_filt_n,f2_filt_n,tc_filt_mm,rr,ra,dr_mm,\
         da_mm,dr_sigma_mm,da_sigma_mm,status,method,handover_z,handover_n,true_dr_mm,true_da_mm,\
         true_tc_mm\n"
    ));
    // A bad status is named.
    let bad = text.replacen(",valid,", ",broken,", 1);
    let mut rd = RecordReader::new(Cursor::new(bad), "r.csv").expect("header");
    let e = loop {
        match rd.next_row() {
            Ok(Some(_)) => continue,
            Ok(None) => panic!("the bad status was read"),
            Err(e) => break e,
        }
    };
    assert!(
        format!("{e:#}").contains("column `status`: `broken`"),
        "{e:#}"
    );
}

#[test]
fn bits_lines_are_target_checks_format() {
    // tests/target-check's write_case: index in decimal, then " {word:08x}" per word.
    assert_eq!(bits_line(0, &[]), "0\n");
    assert_eq!(
        bits_line(7, &[1, 0xdead_beef, 0]),
        "7 00000001 deadbeef 00000000\n"
    );
    let trace = synthetic_trace(0.5, true);
    let cfg = config_for(&trace, "");
    let mut out = Vec::new();
    let (summary, _, _) = replay_to(
        &mut reader(&trace),
        &cfg,
        &mut out,
        RecordFormat::Bits,
        &ReplayOutputs::default(),
        None,
    )
    .expect("replays");
    let text = String::from_utf8(out).expect("utf8");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len() as u64, summary.records);
    for (i, l) in lines.iter().enumerate() {
        let f: Vec<&str> = l.split(' ').collect();
        assert_eq!(f[0], i.to_string());
        assert_eq!(f.len(), 1 + estimator_core::monitor::RECORD_WORDS);
        assert!(f[1..].iter().all(|w| w.len() == 8));
    }
}

#[test]
fn plot_renders_png_and_svg() {
    let trace = synthetic_trace(1.0, true);
    let cfg = config_for(&trace, "");
    let (_, data, _) = replay_to(
        &mut reader(&trace),
        &cfg,
        Vec::new(),
        RecordFormat::Csv,
        &ReplayOutputs {
            plot: true,
            ..Default::default()
        },
        None,
    )
    .expect("replays");
    let mut data = data.expect("plot data");
    data.alarms.push(0.5);
    let png = plot::render(&data, PlotFormat::Png).expect("png");
    assert!(
        png.len() > 10_000 && png.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{}",
        png.len()
    );
    let svg = plot::render(&data, PlotFormat::Svg).expect("svg");
    let svg = String::from_utf8(svg).expect("utf8");
    assert!(svg.contains("<svg") && svg.contains("radial depth"));
    assert!(PlotFormat::from_path(std::path::Path::new("x.jpg")).is_err());
    assert!(plot::render(&plot::PlotData::default(), PlotFormat::Png).is_err());
}

/// A fresh directory for one test's files.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

#[test]
fn command_line_writes_records_plot_and_bin() {
    let dir = scratch("replay-cli");
    let trace = dir.join("trace.csv");
    std::fs::write(&trace, synthetic_trace(1.0, true)).expect("trace");
    let exe = env!("CARGO_BIN_EXE_host-sim");
    let run = |args: &[&str]| {
        std::process::Command::new(exe)
            .args(args)
            .output()
            .expect("runs")
    };
    let p = |f: &str| dir.join(f).display().to_string();
    let out = run(&[
        "replay",
        "--trace",
        &p("trace.csv"),
        "--output",
        &p("records.csv"),
        "--plot",
        &p("plot.png"),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("tooth records") && stderr.contains("d_a vs the window-mean truth"),
        "{stderr}"
    );
    for f in ["records.csv", "plot.png"] {
        let len = std::fs::metadata(dir.join(f)).expect(f).len();
        assert!(len > 1000, "{f}: {len} bytes");
    }
    assert!(!dir.join("records.csv.partial").exists());
    let out = run(&[
        "trace-bin",
        "--trace",
        &p("trace.csv"),
        "--output",
        &p("t.bin"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::metadata(dir.join("t.bin")).expect("bin").len(),
        12 + 24 * 20_000
    );
    // A failing run leaves no output behind.
    let out = run(&[
        "replay",
        "--trace",
        &p("trace.csv"),
        "--config",
        &p("missing.toml"),
        "--output",
        &p("never.csv"),
    ]);
    assert!(!out.status.success());
    assert!(!dir.join("never.csv").exists() && !dir.join("never.csv.partial").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A drop trip latches the output inside a tooth period and a later record names the
/// cause: the summary's alarm time and latency, the events CSV's `latched_s` and the
/// plot's alarm line run to the sample where the output latched, the first one after
/// which a sample-by-sample run of the same trace finds the alarm state latched; the
/// naming record's time stays in `time_s`. On the first break case at seed 1 whose alarm
/// latched inside a period (which the rules on the records catch first moves with them).
#[test]
fn a_drop_trip_is_reported_where_the_output_latched() {
    let dir = scratch("replay-trip");
    let trace = dir.join("trace.csv");
    let replayed = |index: usize| {
        let case = draw_case(Kind::Break, index, 1).expect("a break case");
        let f = std::io::BufWriter::new(std::fs::File::create(&trace).expect("create"));
        host_sim::sim::write_trace(&case.scenario, f).expect("simulate");
        let machine = MachineConfig {
            monitor: case.machine.monitor.clone(),
            alarms: case.machine.alarms,
            front_end: FrontEnd::default(),
        };
        let pipeline = machine.clone().build().expect("builds");
        let mut st = PipelineState::default();
        let mut rd = TraceReader::open(&trace).expect("open");
        let mut first = None;
        while let Some(row) = rd.next_row().expect("row") {
            let _ = pipeline.process(&mut st, &row.to_sample());
            if first.is_none() && st.alarms.output_latched() {
                first = Some(row.time_s);
            }
        }
        let first = first.expect("the output latched");

        let mut rd = TraceReader::open(&trace).expect("open");
        let outputs = ReplayOutputs {
            plot: true,
            alarms: machine.alarms,
            events: true,
        };
        let (sum, plot, events) = replay_to(
            &mut rd,
            &machine.monitor,
            std::io::sink(),
            RecordFormat::Csv,
            &outputs,
            None,
        )
        .expect("replay");
        (first, sum, plot, events)
    };
    let (first, sum, plot, events) = (0..40)
        .map(replayed)
        .find(|r| r.1.first_alarm.is_some_and(|a| a.latched_s < a.time_s))
        .expect("a trip inside a period in the first 40 break cases");
    let a = sum.first_alarm.expect("an alarm");
    let close = |x: f64| (x - first).abs() < 1e-6;
    assert!(close(a.latched_s), "{} vs {first}", a.latched_s);
    let damage = sum.damage_s.expect("the truth shows the break");
    assert_eq!(a.latency_s, Some(a.latched_s - damage));
    let report = sum.report("trace");
    assert!(
        report.contains(&format!("at {:.4} s", a.latched_s)),
        "{report}"
    );

    let mut lines = events.lines();
    assert_eq!(lines.next(), Some(replay::ALARM_COLUMNS));
    let row: Vec<f64> = lines
        .next()
        .expect("an event row")
        .split(',')
        .take(2)
        .map(|c| c.parse().expect("a number"))
        .collect();
    assert_eq!(row[0], a.time_s);
    assert!(close(row[1]), "{row:?} vs {first}");
    let plot = plot.expect("plot data");
    assert!(
        plot.alarms.first().is_some_and(|&t| close(t)),
        "{:?}",
        plot.alarms
    );
}
