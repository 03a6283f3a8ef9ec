//! `host-sim demo` end to end: the built-in cut simulated, replayed, tabulated, plotted.

use estimator_core::alarm::Cause;
use host_sim::demo::{builtin_scenario, run_demo, DemoReport, STEADY_TOLERANCE};
use host_sim::records::RecordReader;
use host_sim::replay::{load_monitor_config, replay_to, RecordFormat, ReplayOutputs};
use host_sim::sim::EventKind;
use host_sim::trace::TraceReader;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn out_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// One run shared by the tests (about a second even in a debug build).
fn report() -> &'static DemoReport {
    static REPORT: OnceLock<DemoReport> = OnceLock::new();
    REPORT.get_or_init(|| {
        let sc = builtin_scenario().expect("the built-in scenario parses");
        let r = run_demo(&sc, "cut.toml", &out_dir("demo")).expect("the demo runs");
        eprintln!("{}", r.text());
        r
    })
}

#[test]
fn builtin_scenario_is_the_committed_example() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/cut.toml");
    let on_disk = std::fs::read_to_string(path).expect("examples/cut.toml");
    assert_eq!(on_disk, host_sim::demo::SCENARIO_TEXT);
    let sc = builtin_scenario().expect("parses");
    // What the demo is meant to show.
    let labels: Vec<_> = sc
        .segments
        .iter()
        .map(|s| s.label.clone().unwrap_or_default())
        .collect();
    for want in ["radial ramp", "axial step", "feed change"] {
        assert!(labels.iter().any(|l| l.contains(want)), "{labels:?}");
    }
    // The facts `demo --help` states about it.
    let segs = sc.resolve().expect("resolves");
    assert_eq!(segs[0].rpm, (600.0, 600.0));
    assert_eq!((sc.tool.radius_mm, sc.tool.flutes), (8.0, 4));
    assert_eq!(sc.signal.adc_bits, Some(12));
    assert!(segs.iter().any(|g| g.dr == (4.0, 8.0)));
    assert!(segs.iter().any(|g| g.da == (4.0, 6.0)));
    assert!(segs.iter().any(|g| g.feed == (360.0, 540.0)));
    assert!(sc
        .events
        .iter()
        .any(|e| e.kind == EventKind::Break && e.flute == 2 && e.time_s == 11.49));
    let help = host_sim::demo::DEMO_HELP;
    for want in [
        "600 rpm",
        "4 -> 8 mm",
        "4 -> 6 mm",
        "flute 2 breaking at 11.49 s",
    ] {
        assert!(help.contains(want), "`{want}` not in the help");
    }
}

#[test]
fn demo_writes_its_files() {
    let r = report();
    let f = &r.files;
    for p in [&f.trace, &f.records, &f.alarms, &f.machine, &f.plot] {
        let len = std::fs::metadata(p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .len();
        assert!(len > 0, "{} is empty", p.display());
        let mut partial = p.as_os_str().to_owned();
        partial.push(".partial");
        assert!(!Path::new(&partial).exists(), "{partial:?} left behind");
    }
    let png = std::fs::read(&f.plot).expect("read the plot");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "a PNG");
    // Records: one per tooth period, with the truth columns.
    let mut rd = RecordReader::new(std::fs::File::open(&f.records).expect("open"), "records")
        .expect("records header");
    assert!(rd.has_truth());
    let mut n = 0;
    while rd.next_row().expect("row").is_some() {
        n += 1;
    }
    assert_eq!(n, r.replay.records);
    assert!(n > 400, "{n} records");
    let events = std::fs::read_to_string(&f.alarms).expect("alarms");
    assert!(events
        .lines()
        .nth(1)
        .is_some_and(|l| l.contains("breakage")));
    // The text names every file and every segment.
    let text = r.text();
    for p in [&f.trace, &f.records, &f.plot] {
        let name = p.file_name().and_then(|s| s.to_str()).expect("name");
        assert!(text.contains(name), "{name} not in\n{text}");
    }
    for g in &r.segments {
        assert!(text.contains(&g.label), "{} not in\n{text}", g.label);
    }
}

#[test]
fn the_alarm_is_a_breakage_within_one_revolution_of_the_break() {
    let r = report();
    let damage = r.damage.expect("the scenario breaks a flute");
    assert_eq!(damage.kind, EventKind::Break);
    let a = r.replay.first_alarm.expect("an alarm");
    assert_eq!(a.event.cause, Cause::Breakage, "{a:?}");
    let latency = r.alarm_latency_s().expect("latency");
    let rev_s = 60.0 / f64::from(a.event.record.rpm);
    assert!(
        latency > 0.0 && latency <= rev_s,
        "alarm {latency:.4} s after the break; a revolution is {rev_s:.4} s"
    );
    assert!(r.replay.damage_s.is_some_and(|d| d <= a.time_s));
    assert!(r.text().contains("alarm: breakage"));
}

#[test]
fn steady_segments_estimate_the_truth_within_5_percent() {
    let r = report();
    let steady: Vec<_> = r.segments.iter().filter(|g| g.steady).collect();
    assert!(steady.len() >= 2, "{:#?}", r.segments);
    for g in steady {
        assert!(g.valid >= 10, "{}: {} valid records", g.label, g.valid);
        let (edr, eda) = g.rel_errors();
        assert!(
            edr.abs() < STEADY_TOLERANCE && eda.abs() < STEADY_TOLERANCE,
            "{}: d_r {:.3} vs {:.3}, d_a {:.3} vs {:.3}",
            g.label,
            g.est_dr_mm,
            g.true_dr_mm,
            g.est_da_mm,
            g.true_da_mm
        );
        // The band is a real one: finite, positive, and small against the depth.
        assert!(g.dr_2sigma_mm > 0.0 && g.dr_2sigma_mm < 0.05 * g.true_dr_mm);
        assert!(g.da_2sigma_mm > 0.0 && g.da_2sigma_mm < 0.05 * g.true_da_mm);
    }
    // Every valid record, steady or not, against its window's truth.
    for g in r.segments.iter().filter(|g| g.valid > 0) {
        assert!(
            g.dr_err.abs() < STEADY_TOLERANCE && g.da_err.abs() < STEADY_TOLERANCE,
            "{g:?}"
        );
    }
}

#[test]
fn the_machine_file_repeats_the_replay() {
    let r = report();
    let f = &r.files;
    let mut reader = TraceReader::open(&f.trace).expect("trace");
    let rate = reader.detect_sample_rate_hz().expect("rate");
    let loaded = load_monitor_config(Some(&f.machine), rate).expect("machine file");
    assert_eq!(loaded.config, r.machine.monitor);
    assert_eq!(loaded.alarms, r.machine.alarms);
    let outputs = ReplayOutputs {
        alarms: loaded.alarms,
        ..ReplayOutputs::default()
    };
    let (summary, _, _) = replay_to(
        &mut reader,
        &loaded.config,
        Vec::new(),
        RecordFormat::Csv,
        &outputs,
        None,
    )
    .expect("replay");
    assert_eq!(summary, r.replay);
}

#[test]
fn a_scenario_the_estimator_cannot_invert_is_refused() {
    let text =
        host_sim::demo::SCENARIO_TEXT.replace("material = \"table2\"", "material = \"al6061\"");
    let sc = host_sim::sim::Scenario::from_toml(&text, "al.toml").expect("parses");
    let err = run_demo(&sc, "al.toml", &out_dir("demo-al")).expect_err("refused");
    assert!(format!("{err:#}").contains("power-law"), "{err:#}");
}
