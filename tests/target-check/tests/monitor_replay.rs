//! The streaming Monitor on thumbv7em (QEMU) against host-sim's replay of the same trace:
//! the two record streams must be identical bit for bit.
//!
//! 1. the synthetic trace (`common`) is written as a raw trace CSV by host-sim's
//!    `TraceWriter`;
//! 2. host-sim's `write_sample_bin` (what `host-sim trace-bin` runs) makes the TMS1 blob;
//! 3. `monitor-replay` is built with `TRACE_BIN` pointing at it and run in QEMU;
//! 4. host-sim's replay of the CSV (`replay_to` in `--bits` form, with the configuration
//!    `host-sim replay` loads when given none) is compared with QEMU's lines: same count,
//!    not empty, identical, with both valid and flagged records among them.
//!
//! The QEMU test is ignored by default (cross build, QEMU); `tests/all.sh` runs it.

mod common;

use common::Summary;
use host_sim::replay::{load_monitor_config, replay_to, RecordFormat, ReplayOutputs};
use host_sim::trace::{
    write_sample_bin, FeedSignal, SpindleSignal, TraceKind, TraceReader, TraceRow, TraceWriter,
    Truth,
};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;
use target_check::host::{build_elfs, qemu_target_dir, run_qemu, QemuConfig};

/// Writes the synthetic trace as a raw trace CSV with host-sim's writer.
fn write_csv(rows: &[common::SynthRow], path: &Path) {
    let kind = TraceKind {
        feed: FeedSignal::Current,
        two_axis: false,
        has_velocity: true,
        spindle: SpindleSignal::Current,
        has_truth: true,
    };
    let f = BufWriter::new(File::create(path).expect("create trace CSV"));
    let mut w = TraceWriter::new(f, kind, f64::from(common::SAMPLE_RATE_HZ)).expect("header");
    for r in rows {
        let s = r.sample;
        let row = TraceRow {
            time_s: r.time_s,
            sync: s.sync,
            feed: s.feed,
            feed_velocity_mm_min: s.feed_velocity_mm_min,
            spindle: s.spindle,
            truth: Truth {
                dr_mm: r.dr_mm,
                da_mm: r.da_mm,
                tc_mm: r.tc_mm,
                rpm: common::RPM,
                flutes_intact: 0b1111,
                fx_n: r.forces_n[0],
                fy_n: r.forces_n[1],
                ft_n: r.forces_n[2],
            },
        };
        w.write_row(&row).expect("write row");
    }
    w.finish().expect("flush trace CSV");
}

/// `host-sim trace-bin --trace csv --output bin`, as a library call.
fn trace_bin(csv: &Path, bin: &Path) -> Vec<u8> {
    let mut reader = TraceReader::open(csv).expect("open trace CSV");
    let out = BufWriter::new(File::create(bin).expect("create blob"));
    write_sample_bin(&mut reader, out).expect("trace-bin");
    std::fs::read(bin).expect("read blob back")
}

/// `host-sim replay --trace csv --bits`, as a library call: the record lines.
fn host_sim_replay(csv: &Path) -> Vec<String> {
    let mut reader = TraceReader::open(csv).expect("open trace CSV");
    let rate = reader.detect_sample_rate_hz().expect("read ahead");
    let cfg = load_monitor_config(None, rate)
        .expect("default config")
        .config;
    let mut out = Vec::new();
    let (summary, _, _) = replay_to(
        &mut reader,
        &cfg,
        &mut out,
        RecordFormat::Bits,
        &ReplayOutputs::default(),
        None,
    )
    .expect("host-sim replay");
    let text = String::from_utf8(out).expect("ASCII lines");
    let lines: Vec<String> = text.lines().map(str::to_owned).collect();
    assert_eq!(summary.records as usize, lines.len());
    lines
}

fn trace_dir() -> PathBuf {
    let dir = qemu_target_dir().join("trace");
    std::fs::create_dir_all(&dir).expect("create target/qemu/trace");
    dir
}

/// Fails with the first differing line, then on a count mismatch.
fn assert_same(what: &str, a: &[String], b: &[String]) {
    if let Some((i, (x, y))) = a.iter().zip(b).enumerate().find(|(_, (x, y))| x != y) {
        panic!("{what}: first difference at record {i}:\n  left:  {x}\n  right: {y}");
    }
    assert_eq!(a.len(), b.len(), "{what}: record counts differ");
}

#[test]
fn synthetic_trace_exercises_the_status_paths() {
    let rows = common::rows();
    let blob = common::blob(&rows);
    let mut report = String::new();
    let n = target_check::write_replay_report(&mut report, &blob).expect("replay");
    let lines = common::case_lines("native", &report);
    assert_eq!(n as usize, lines.len());
    let s = Summary::of(&lines);
    eprintln!("{s}");
    assert!(s.valid >= 40, "{s}");
    for flag in [
        "not_cutting",
        "period_invalid",
        "input_fault",
        "transient",
        "feed_change",
        "settling",
    ] {
        let n = s.flags.iter().find(|(f, _)| *f == flag).map_or(0, |f| f.1);
        assert!(n > 0, "no `{flag}` record: {s}");
    }
}

#[test]
fn host_sim_blob_and_replay_match_target_check_natively() {
    // Without QEMU: the blob host-sim writes is the one target-check encodes, and the
    // target's report code run natively gives host-sim's lines. A failure here is a
    // format or replay-config disagreement, not a thumbv7em one.
    let rows = common::rows();
    let dir = trace_dir();
    let csv = dir.join("native-check.csv");
    write_csv(&rows, &csv);
    let blob = trace_bin(&csv, &dir.join("native-check.tms1"));
    assert!(
        blob == common::blob(&rows),
        "host-sim's TMS1 blob differs from target-check's encoding"
    );
    let mut report = String::new();
    target_check::write_replay_report(&mut report, &blob).expect("native replay");
    assert_same(
        "host-sim replay vs target-check's report on the host",
        &host_sim_replay(&csv),
        &common::case_lines("native", &report),
    );
}

#[test]
#[ignore = "cross-builds for thumbv7em and needs qemu-system-arm (run by tests/all.sh)"]
fn monitor_on_qemu_matches_host_sim_replay_bit_for_bit() {
    let rows = common::rows();
    let dir = trace_dir();
    let csv = dir.join("monitor-replay.csv");
    let bin = dir.join("monitor-replay.tms1");
    write_csv(&rows, &csv);
    let blob = trace_bin(&csv, &bin);
    eprintln!(
        "trace: {} samples, blob {} bytes at {}",
        rows.len(),
        blob.len(),
        bin.display()
    );

    let t = Instant::now();
    let elf = build_elfs(
        "target-check",
        &["monitor-replay"],
        &[("TRACE_BIN", bin.as_os_str())],
    )
    .pop()
    .expect("one ELF");
    eprintln!("cross build: {:.1} s", t.elapsed().as_secs_f64());
    let run = run_qemu(&elf, &QemuConfig::default());
    eprintln!("qemu run: {:.2} s", run.elapsed.as_secs_f64());
    assert!(
        run.success(),
        "QEMU run failed (exit code {:?}, timed out: {})\n--- stdout ---\n{}\n--- stderr ---\n{}",
        run.code,
        run.timed_out,
        run.stdout,
        run.stderr
    );
    let target = common::case_lines("target", &run.stdout);
    let host = host_sim_replay(&csv);

    assert!(!host.is_empty(), "host-sim replay gave no records");
    assert_same(
        "host-sim replay (left) vs thumbv7em in QEMU (right)",
        &host,
        &target,
    );
    let s = Summary::of(&target);
    eprintln!("identical on host and thumbv7em: {s}");
    assert!(s.valid > 0, "no valid record: {s}");
    assert!(s.valid < s.records, "no flagged record: {s}");

    // A blob that is not TMS1 is refused on the target: message, failing exit, no report.
    // (Same test function: another build with a different TRACE_BIN must not run alongside.)
    let bad = dir.join("bad-magic.tms1");
    let mut bytes = blob[..12 + 24 * 10].to_vec();
    bytes[..4].copy_from_slice(b"TMS0");
    std::fs::write(&bad, &bytes).expect("write bad blob");
    let elf = build_elfs(
        "target-check",
        &["monitor-replay"],
        &[("TRACE_BIN", bad.as_os_str())],
    )
    .pop()
    .expect("one ELF");
    let run = run_qemu(&elf, &QemuConfig::default());
    assert!(
        !run.timed_out && run.code == Some(1) && run.stderr.contains("not a TMS1 blob"),
        "a bad magic must fail with a message (exit code {:?})\n--- stdout ---\n{}\n--- stderr ---\n{}",
        run.code,
        run.stdout,
        run.stderr
    );
    assert!(
        !run.stdout.contains(target_check::BEGIN),
        "no report for a bad blob"
    );
}
