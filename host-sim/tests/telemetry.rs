//! `host-sim decode-telemetry`: captures made by the firmware library's own encoder decode
//! into replay's records CSV, bit for bit, with every loss counted.

use estimator_core::alarm::AlarmConfig;
use estimator_core::{MachineConfig, PipelineState};
use firmware::telemetry::{AlarmFields, Counters, EventFields, RecordFrame, RECORD_FRAME_BYTES};
use host_sim::records::RecordReader;
use host_sim::replay::{load_monitor_config, replay_to, RecordFormat, ReplayOutputs};
use host_sim::sim::Scenario;
use host_sim::telemetry::decode_to_csv;
use host_sim::trace::TraceReader;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A short steady cut with a flute breaking, at 5 kS/s (the default board).
const SCENARIO: &str = r#"
sample_rate_hz = 5000.0
seed = 3
[tool]
radius_mm = 8.0
flutes = 4
helix_deg = 30.0
[signal]
feed_noise = 0.002
spindle_noise = 0.005
[[segment]]
duration_s = 1.6
rpm = 1200.0
feed_mm_min = 720.0
dr_mm = 4.0
da_mm = 4.0
[[event]]
time_s = 1.2
flute = 2
kind = "break"
"#;

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&d).expect("tmp dir");
    d
}

/// The scenario's trace CSV, and the frames the board would send for it: the pipeline
/// over the trace's samples, every record encoded by the firmware library.
fn capture(d: &Path) -> (PathBuf, Vec<RecordFrame>) {
    let sc = Scenario::from_toml(SCENARIO, "SCENARIO").expect("scenario");
    let csv = d.join("trace.csv");
    let f = std::io::BufWriter::new(std::fs::File::create(&csv).expect("create"));
    host_sim::sim::write_trace(&sc, f).expect("simulate");
    let mut rd = TraceReader::open(&csv).expect("open");
    let rate = rd.detect_sample_rate_hz().expect("rate");
    let cfg = load_monitor_config(None, rate)
        .expect("default config")
        .config;
    let pipeline = MachineConfig {
        monitor: cfg.clone(),
        alarms: AlarmConfig::default(),
        front_end: estimator_core::FrontEnd::default(),
    }
    .build()
    .expect("builds");
    let mut st = PipelineState::default();
    let mut frames = Vec::new();
    while let Some(row) = rd.next_row().expect("row") {
        if let Some((rec, a)) = pipeline.process(&mut st, &row.to_sample()) {
            let n = frames.len() as u32;
            frames.push(RecordFrame {
                seq: n,
                index: n,
                sample_rate_hz: cfg.sample_rate_hz,
                record: rec,
                alarm: AlarmFields {
                    latched: a.latched,
                    wear_warning: a.wear_warning,
                    event: a.event.as_ref().map(EventFields::from),
                    wear: a.wear,
                },
                counters: Counters::default(),
            });
        }
    }
    (csv, frames)
}

#[test]
fn a_clean_capture_decodes_into_replays_records() {
    let d = dir("telemetry-clean");
    let (csv, frames) = capture(&d);
    let mut bytes = Vec::new();
    for f in &frames {
        bytes.extend(f.encode());
    }
    let mut events = String::new();
    let (sum, out) = decode_to_csv(&bytes, Vec::new(), Some(&mut events)).expect("decodes");
    assert_eq!(sum.stats.frames as usize, frames.len());
    assert!(!sum.lossy(), "{sum:?}");
    assert_eq!(sum.not_sent, 0);
    assert_eq!(sum.alarm_events, 1, "{events}");
    let mut ev = events.lines().skip(1);
    let breakage = ev.next().expect("one event row");
    assert!(breakage.contains(",breakage,"), "{breakage}");
    assert!(ev.next().is_none());
    assert!(sum.latched_frames > 0);

    // The same rows as `host-sim replay` of the trace, every word of every record.
    let mut rd = TraceReader::open(&csv).expect("open");
    let rate = rd.detect_sample_rate_hz().expect("rate");
    let cfg = load_monitor_config(None, rate).expect("config").config;
    let mut replayed = Vec::new();
    let outputs = ReplayOutputs {
        events: true,
        ..ReplayOutputs::default()
    };
    let (_, _, replayed_events) = replay_to(
        &mut rd,
        &cfg,
        &mut replayed,
        RecordFormat::Csv,
        &outputs,
        None,
    )
    .expect("replay");
    // The events file too: the same columns, the times (the record's, and the latch's,
    // which the frame carries as its lead) to the trace's time stamps' last bits.
    assert_eq!(events.lines().count(), replayed_events.lines().count());
    for (x, y) in events.lines().zip(replayed_events.lines()) {
        let (x, y): (Vec<&str>, Vec<&str>) = (x.split(',').collect(), y.split(',').collect());
        assert_eq!(x.len(), y.len());
        for (k, (a, b)) in x.iter().zip(&y).enumerate() {
            match (k, a.parse::<f64>(), b.parse::<f64>()) {
                (0 | 1, Ok(a), Ok(b)) => assert!((a - b).abs() <= 1e-9, "{x:?} vs {y:?}"),
                _ => assert_eq!(a, b, "{x:?} vs {y:?}"),
            }
        }
    }
    let mut a = RecordReader::new(&out[..], "decoded").expect("decoded CSV");
    let mut b = RecordReader::new(&replayed[..], "replayed").expect("replayed CSV");
    assert!(!a.has_truth());
    let mut n = 0;
    while let Some(x) = a.next_row().expect("decoded row") {
        let y = b.next_row().expect("replayed row").expect("as many rows");
        // The simulator's time stamps may differ from `end_sample / rate` in the last bit.
        assert!(
            (x.time_s - y.time_s).abs() <= 1e-12 * y.time_s.abs().max(1.0),
            "row {n}: {} vs {}",
            x.time_s,
            y.time_s
        );
        assert_eq!(x.record.to_words(), y.record.to_words(), "row {n}");
        n += 1;
    }
    assert!(b.next_row().expect("end").is_none());
    assert_eq!(n, frames.len());
}

#[test]
fn losses_are_counted_not_dropped() {
    let d = dir("telemetry-lossy");
    let (_, mut frames) = capture(&d);
    frames.truncate(40);
    // Decimation on the board: from frame 30 on, one record is not sent between frames;
    // and the board counted losses of its own.
    for (k, f) in frames.iter_mut().enumerate().skip(30) {
        f.index += k as u32 - 29;
        f.counters = Counters {
            samples_lost: 3,
            edges_late: 1,
            edges_dropped: 2,
            frames_dropped: 5,
        };
    }
    let mut bytes = b"boot".to_vec();
    for (k, f) in frames.iter().enumerate() {
        let mut b = f.encode();
        match k {
            5 => b[60] ^= 0x01,  // corrupted: bad CRC
            10 | 11 => continue, // lost on the wire
            _ => {}
        }
        bytes.extend(b);
    }
    bytes.extend(&frames[0].encode()[..50]); // cut off
    let (sum, out) = decode_to_csv(&bytes, Vec::new(), None).expect("decodes");
    let s = sum.stats;
    assert_eq!(s.frames, 40 - 3);
    assert_eq!(s.bad_crc, 1);
    // 5 (bad CRC), 10, 11, and the cut-off frame's sequence number is never seen.
    assert_eq!(s.missing, 3);
    assert!(s.truncated);
    assert_eq!(s.skipped_bytes, 4 + RECORD_FRAME_BYTES as u64 + 50);
    assert_eq!(sum.counters.frames_dropped, 5);
    assert_eq!(sum.not_sent, 10, "frames 30..=39 each skip one record");
    assert!(sum.lossy());
    let report = sum.report("capture.bin");
    for want in [
        "37 record frames",
        "1 bad CRC",
        "3 frames missing",
        "last frame truncated",
        "3 samples lost",
        "5 frames dropped",
        "warning",
    ] {
        assert!(report.contains(want), "`{want}` not in\n{report}");
    }
    let mut rd = RecordReader::new(&out[..], "decoded").expect("CSV");
    let mut n = 0;
    while rd.next_row().expect("row").is_some() {
        n += 1;
    }
    assert_eq!(n, 37);
}

#[test]
fn the_command_reports_on_stderr_and_refuses_what_is_not_a_capture() {
    let d = dir("telemetry-cli");
    let (_, frames) = capture(&d);
    let mut bytes = b"noise".to_vec();
    for f in &frames {
        bytes.extend(f.encode());
    }
    let input = d.join("capture.bin");
    std::fs::write(&input, &bytes).expect("write capture");
    let output = d.join("records.csv");
    let alarms = d.join("alarms.csv");
    let _ = std::fs::remove_file(&output);
    let exe = env!("CARGO_BIN_EXE_host-sim");
    let run = |args: &[&Path], extra: &[&str]| {
        let mut c = Command::new(exe);
        c.arg("decode-telemetry").arg("--input").arg(args[0]);
        if let Some(o) = args.get(1) {
            c.arg("--output").arg(o);
        }
        if let Some(a) = args.get(2) {
            c.arg("--alarms").arg(a);
        }
        c.args(extra).output().expect("runs host-sim")
    };
    let o = run(&[&input, &output, &alarms], &[]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("{} record frames", frames.len())),
        "{stderr}"
    );
    assert!(stderr.contains("5 bytes skipped"), "{stderr}");
    let csv = std::fs::read_to_string(&output).expect("records written");
    assert_eq!(csv.lines().count(), frames.len() + 1);
    assert!(std::fs::read_to_string(&alarms)
        .expect("alarms written")
        .contains("breakage"));

    // --strict: skipped bytes are a loss.
    let o = run(&[&input, &output], &["--strict"]);
    assert!(!o.status.success());

    // Not a capture: an error, and no output file.
    let junk = d.join("junk.bin");
    std::fs::write(&junk, vec![0x55u8; 4000]).expect("write junk");
    let none = d.join("none.csv");
    let _ = std::fs::remove_file(&none);
    let o = run(&[&junk, &none], &[]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(stderr.contains("no telemetry frame"), "{stderr}");
    assert!(!none.exists());
}
