//! The firmware's task graph (firmware-qemu) in QEMU against the host: the same records bit
//! for bit, the same latch after each, the breakage alarm on the same record (its value,
//! threshold and latch, bit for bit); and, under
//! `-icount`, its instruction counts, sizes and stack (written to
//! `target/qemu/firmware-qemu.md` for BENCHMARKS.md).
//!
//! The QEMU tests are ignored by default (cross build, QEMU); `tests/all.sh` runs them.

use std::fmt::Write as _;
use std::time::Instant;

use estimator_core::alarm::{Cause, TRIP_NAMED_WITHIN};
use estimator_core::Status;
use firmware_qemu_check::{
    decode_frames, frames_from_report, host_pipeline, host_sim_replay, make_trace, qemu_stats,
    HostRecord, BREAK_TIME_S,
};
use target_check::host::{build_elfs, llvm_size, qemu_target_dir, run_qemu, QemuConfig};

/// Instructions per SysTick cycle under `-icount shift=0`: 1 ns per instruction, SysTick at
/// the modelled 168 MHz core clock.
const INSTR_PER_CYCLE: f64 = 1e9 / 168e6;

/// The first record that raised `cause`.
fn first_event(records: &[HostRecord], cause: Cause) -> Option<usize> {
    records.iter().position(|r| r.event == Some(cause))
}

#[test]
fn host_reference_sees_the_break_and_matches_host_sim_replay() {
    let dir = qemu_target_dir().join("firmware-trace");
    let t = make_trace(&dir, "native");
    let host = host_pipeline(t.sample_rate_hz, &t.samples);
    let replay = host_sim_replay(&t.csv);
    let words: Vec<_> = host.iter().map(|r| r.words).collect();
    assert_eq!(words, replay, "the core's pipeline vs host-sim replay");
    let valid = host
        .iter()
        .filter(|r| Status(r.words[17] as u16).is_valid())
        .count();
    let k = first_event(&host, Cause::Breakage).expect("the breakage alarm fires");
    let end = host[k].words[0] as f64 / t.sample_rate_hz as f64;
    eprintln!(
        "{} records, {valid} valid, breakage at record {k} (t = {end:.3} s, break at \
         {BREAK_TIME_S} s)",
        host.len()
    );
    assert!(valid > 50, "{valid} valid records");
    assert!(
        end > BREAK_TIME_S && end < BREAK_TIME_S + 0.1,
        "breakage raised at {end} s"
    );
    assert!(
        host[..k].iter().all(|r| r.event.is_none()),
        "nothing raised before the break"
    );
    // A drop trip inside a period latches the output before the record that names it (at
    // most TRIP_NAMED_WITHIN records before), never before the break.
    let first = host.iter().position(|r| r.latched).expect("latched");
    let first_end = host[first].words[0] as f64 / t.sample_rate_hz as f64;
    eprintln!("latched from record {first} (t = {first_end:.3} s)");
    assert!(
        first <= k && k - first < TRIP_NAMED_WITHIN as usize && first_end > BREAK_TIME_S,
        "latched at record {first}, {first_end} s"
    );
    assert!(
        host[first..].iter().all(|r| r.latched),
        "latched from then on"
    );
}

/// The decoder host-sim gets: the host pipeline's records as telemetry frames (with
/// garbage before and a frame cut short after) decode into the records CSV that host-sim
/// replay writes, row for row.
#[test]
fn a_telemetry_capture_decodes_into_replays_records_csv() {
    use firmware::telemetry::{AlarmFields, Counters, RecordFrame};
    use host_sim::records::RecordReader;
    let dir = qemu_target_dir().join("firmware-trace");
    let t = make_trace(&dir, "decode");
    let host = host_pipeline(t.sample_rate_hz, &t.samples);
    let mut capture = b"boot noise".to_vec();
    for (i, h) in host.iter().enumerate() {
        let f = RecordFrame {
            seq: i as u32,
            index: i as u32,
            sample_rate_hz: t.sample_rate_hz,
            record: firmware::telemetry::record_from_words(&h.words).expect("known method"),
            alarm: AlarmFields::default(),
            counters: Counters::default(),
        };
        capture.extend(f.encode());
    }
    capture.extend(&capture[20..70].to_vec());
    let (stats, csv) =
        firmware_qemu_check::decode_telemetry_to_csv(&capture, Vec::new()).expect("decodes");
    assert_eq!(stats.frames as usize, host.len());
    assert!(stats.truncated && stats.missing == 0 && stats.bad_crc == 0);

    let replay_csv = dir.join("decode-replay.csv");
    let mut reader = host_sim::trace::TraceReader::open(&t.csv).expect("open trace");
    let rate = reader.detect_sample_rate_hz().expect("rate");
    let cfg = host_sim::replay::load_monitor_config(None, rate)
        .expect("config")
        .config;
    let f = std::fs::File::create(&replay_csv).expect("create");
    host_sim::replay::replay_to(
        &mut reader,
        &cfg,
        std::io::BufWriter::new(f),
        host_sim::replay::RecordFormat::Csv,
        &host_sim::replay::ReplayOutputs::default(),
        None,
    )
    .expect("replay");
    let mut a = RecordReader::new(&csv[..], "decoded").expect("decoded CSV");
    let mut b = RecordReader::new(std::fs::File::open(&replay_csv).expect("open"), "replay")
        .expect("replay CSV");
    let mut rows = 0;
    while let Some(x) = a.next_row().expect("decoded row") {
        let y = b.next_row().expect("replay row").expect("as many rows");
        // The trace's own time stamps (the simulator's) may differ from
        // `end_sample / rate` in the last bit.
        assert!(
            (x.time_s - y.time_s).abs() <= 1e-12 * y.time_s.abs().max(1.0),
            "row {rows}: time {} vs {}",
            x.time_s,
            y.time_s
        );
        assert_eq!(x.record.to_words(), y.record.to_words(), "row {rows}");
        rows += 1;
    }
    assert!(b.next_row().expect("end").is_none());
    assert_eq!(rows, host.len());
}

#[test]
#[ignore = "cross-builds for thumbv7em and needs qemu-system-arm (run by tests/all.sh)"]
fn firmware_graph_in_qemu_matches_the_host_bit_for_bit() {
    let dir = qemu_target_dir().join("firmware-trace");
    let t = make_trace(&dir, "firmware-qemu");
    let host = host_pipeline(t.sample_rate_hz, &t.samples);
    assert_eq!(
        host.iter().map(|r| r.words).collect::<Vec<_>>(),
        host_sim_replay(&t.csv),
        "host references disagree"
    );

    // Both bins in one build: the board's ELF is the one `cargo fw` makes (the trace only
    // changes the QEMU one), for the size figures.
    let start = Instant::now();
    let elfs = build_elfs(
        "firmware",
        &["firmware-qemu", "firmware"],
        &[("FIRMWARE_TRACE", t.blob.as_os_str())],
    );
    eprintln!("cross build: {:.1} s", start.elapsed().as_secs_f64());
    let (qemu_elf, board_elf) = (&elfs[0], &elfs[1]);

    let run = run_qemu(qemu_elf, &QemuConfig::default());
    eprintln!("qemu run: {:.2} s", run.elapsed.as_secs_f64());
    assert!(
        run.success(),
        "QEMU run failed (exit code {:?}, timed out: {})\n--- stdout ---\n{}\n--- stderr ---\n{}",
        run.code,
        run.timed_out,
        run.stdout,
        run.stderr
    );
    let (bytes, lines) = frames_from_report(&run.stdout);
    // The capture, as a UART would have carried it, and host-sim's records CSV of it.
    std::fs::write(dir.join("firmware-qemu-telemetry.bin"), &bytes).expect("write capture");
    let csv = std::fs::File::create(dir.join("firmware-qemu-records.csv")).expect("create CSV");
    let (csv_stats, _) =
        firmware_qemu_check::decode_telemetry_to_csv(&bytes, csv).expect("decode to CSV");
    assert_eq!(csv_stats.frames as usize, host.len());
    let (frames, stats) = decode_frames(&bytes);
    assert_eq!(stats.frames as usize, lines, "every line is one good frame");
    assert_eq!(
        (
            stats.missing,
            stats.bad_crc,
            stats.skipped_bytes,
            stats.unsupported
        ),
        (0, 0, 0, 0),
        "{stats:?}"
    );
    let qs = qemu_stats(&run.stderr);
    eprintln!("{qs:?}");
    for k in [
        "samples_lost",
        "edges_late",
        "edges_dropped",
        "frames_dropped",
    ] {
        assert_eq!(qs[k], 0, "{k}");
    }
    assert_eq!(qs["samples"], t.samples.len() as u64);

    // Records: same count, same words, in order; every frame's index is its position.
    assert_eq!(frames.len(), host.len(), "record count");
    for (i, (f, h)) in frames.iter().zip(&host).enumerate() {
        assert_eq!(
            (f.seq, f.index),
            (i as u32, i as u32),
            "sequence of frame {i}"
        );
        assert_eq!(
            f.record.to_words(),
            h.words,
            "record {i}: thumbv7em (left) vs host (right)"
        );
        assert_eq!(f.alarm.latched, h.latched, "latch after record {i}");
        assert_eq!(f.alarm.event, h.event_fields, "event of record {i}");
        assert_eq!(f.sample_rate_hz, t.sample_rate_hz);
    }
    let k = first_event(&host, Cause::Breakage).expect("host raises breakage");
    let qk = frames
        .iter()
        .position(|f| f.alarm.event.map(|e| e.cause) == Some(Cause::Breakage));
    assert_eq!(qk, Some(k), "breakage on the same record");
    // The relay: energised once running, dropped by the alarm, nothing else.
    let relay: Vec<&str> = run
        .stderr
        .lines()
        .filter_map(|l| {
            l.trim_end_matches('\r')
                .strip_prefix("firmware-qemu relay ")
        })
        .collect();
    assert_eq!(relay, ["dropped", "energised", "dropped"], "relay changes");
    eprintln!(
        "identical on host and in QEMU: {} records, breakage at record {k}",
        host.len()
    );

    // The same ELF under -icount: instruction counts of the monitor's work per block.
    let run = run_qemu(
        qemu_elf,
        &QemuConfig {
            icount: true,
            ..QemuConfig::default()
        },
    );
    assert!(run.success(), "icount run failed\n{}", run.stderr);
    let (bytes, _) = frames_from_report(&run.stdout);
    let (icount_frames, _) = decode_frames(&bytes);
    assert_eq!(
        icount_frames, frames,
        "the icount run sends the same frames"
    );
    let qs = qemu_stats(&run.stderr);
    let report = figures(&qs, board_elf, qemu_elf, t.sample_rate_hz, host.len());
    eprintln!("{report}");
    std::fs::write(qemu_target_dir().join("firmware-qemu.md"), report).expect("write report");
}

/// The BENCHMARKS.md tables from the icount run's stats and the two ELFs.
fn figures(
    qs: &std::collections::BTreeMap<String, u64>,
    board_elf: &std::path::Path,
    qemu_elf: &std::path::Path,
    rate: f32,
    records: usize,
) -> String {
    let per = |cycles: &str, n: &str| qs[cycles] as f64 * INSTR_PER_CYCLE / qs[n].max(1) as f64;
    // Blocks without a record: all per-sample work (and the per-block overhead).
    let per_sample = per("plain_cycles", "plain_samples");
    // Blocks with one record: their samples at the per-sample cost, plus one record.
    let one_block = per("one_record_cycles", "one_record_blocks");
    let one_samples = qs["one_record_samples"] as f64 / qs["one_record_blocks"].max(1) as f64;
    let per_record = one_block - one_samples * per_sample;
    let encode = qs["encode_cycles_per_frame"] as f64 * INSTR_PER_CYCLE;
    let frontend = qs["frontend_cycles_per_block"] as f64 * INSTR_PER_CYCLE
        / firmware::config::SAMPLE_BLOCK as f64;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Trace: {} samples at {rate} S/s, {records} records; per block of {} samples.\n",
        qs["samples"],
        firmware::config::SAMPLE_BLOCK
    );
    let _ = writeln!(s, "| quantity (instructions, QEMU -icount) | value |");
    let _ = writeln!(s, "| --- | ---: |");
    let _ = writeln!(
        s,
        "| per sample (blocks that close no record: merge, pipeline, block overhead; {} blocks) | {per_sample:.0} |",
        qs["plain_blocks"]
    );
    let _ = writeln!(
        s,
        "| per tooth record, on top of its samples (pipeline's period close, alarms, frame queued; {} blocks) | {per_record:.0} |",
        qs["one_record_blocks"]
    );
    let _ = writeln!(
        s,
        "| most in one block | {:.0} |",
        qs["max_block_cycles"] as f64 * INSTR_PER_CYCLE
    );
    let _ = writeln!(
        s,
        "| telemetry: encode one record frame (CRC-32 included), telemetry task | {encode:.0} |"
    );
    let _ = writeln!(
        s,
        "| board sampling arithmetic per sample (codes to units, encoder velocity), sampling task | {frontend:.1} |"
    );
    let _ = writeln!(
        s,
        "| stack high-water mark, bytes (painted) | {} |",
        qs["stack_peak_bytes"]
    );
    let _ = writeln!(s);
    let _ = writeln!(s, "| ELF | flash (text + data) | static RAM (data + bss) |");
    let _ = writeln!(s, "| --- | ---: | ---: |");
    for (name, elf) in [
        ("firmware (board)", board_elf),
        ("firmware-qemu (with the trace)", qemu_elf),
    ] {
        match llvm_size(elf) {
            Some(z) => {
                let _ = writeln!(s, "| {name} | {} | {} |", z.flash(), z.static_ram());
            }
            None => {
                let _ = writeln!(s, "| {name} | llvm-size missing | |");
            }
        }
    }
    // Highest tooth rate at a sample rate on a 168 MHz M4 at 1.4 cycles per instruction.
    let ips = 168e6 / 1.4;
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "At 1.4 cycles per instruction (120 M instructions/s at 168 MHz); a sample costs \
         {:.0}, a tooth record {:.0} instructions.\n",
        per_sample + frontend,
        per_record + encode
    );
    let _ = writeln!(s, "| sample rate | max tooth rate, whole CPU (teeth/s) |");
    let _ = writeln!(s, "| ---: | ---: |");
    for fs in [10e3, 20e3, 50e3, 100e3] {
        let teeth = (ips - fs * (per_sample + frontend)) / (per_record + encode);
        let _ = writeln!(s, "| {:.0} kS/s | {:.0} |", fs / 1e3, teeth);
    }
    s
}
