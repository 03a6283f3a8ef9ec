//! The firmware's task graph in QEMU against the host, bit for bit: the pieces of
//! `tests/qemu.rs`.
//!
//! # Design
//!
//! 1. [`SCENARIO`]: host-sim's simulator cuts with the paper's tool until flute 2 breaks;
//!    the raw trace CSV is written by host-sim ([`make_trace`]) and packed into a TMS1 blob
//!    by `host_sim::trace::write_sample_bin` (what `host-sim trace-bin` runs).
//! 2. The host side: `host-sim replay --bits` of the CSV ([`host_sim_replay`]), and the
//!    core's `Pipeline` over the blob's samples with the configuration the firmware builds
//!    ([`host_pipeline`]), which gives the alarms too (replay reports records only).
//! 3. The target side: `firmware-qemu` built with `FIRMWARE_TRACE` = the blob and run in
//!    QEMU; its telemetry frames, one report line of words each ([`frames_from_report`]),
//!    are turned back into the byte stream a UART would carry and decoded by
//!    `firmware::telemetry::decode`, the decoder host-sim uses for a capture.
//!
//! The test then asks for the same records (every word), the same latch state after each,
//! and the breakage alarm on the same record.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use estimator_core::alarm::Cause;
use estimator_core::monitor::RECORD_WORDS;
use estimator_core::Sample;
use firmware::config::BoardConfig;
use firmware::telemetry::{decode, DecodeStats, EventFields, RecordFrame};
use host_sim::replay::{load_monitor_config, replay_to, RecordFormat, ReplayOutputs};
use host_sim::sim::Scenario;
use host_sim::trace::{decode_samples, write_sample_bin, TraceReader};

/// The cut: the paper's 16 mm four-flute end mill in SB40 steel (Table 2), down milling at
/// 1 200 rpm and 0.15 mm/tooth (720 mm/min), `d_r` = `d_a` = 4 mm, on
/// `MonitorConfig::default()`'s drive models (the scenario's default `input`), 5 kS/s
/// (62.5 samples a tooth), with sensor noise and a little runout; flute 2 breaks at 1.5 s.
/// 2.2 s: 11 000 samples, a 264 KB blob.
pub const SCENARIO: &str = r#"
sample_rate_hz = 5000.0
seed = 11

[tool]
radius_mm = 8.0
flutes = 4
helix_deg = 30.0
runout_mm = [0.002, 0.0, -0.001, 0.0]

[signal]
feed_noise = 0.002
spindle_noise = 0.005

[[segment]]
label = "steady cut, then flute 2 breaks"
duration_s = 2.2
rpm = 1200.0
feed_mm_min = 720.0
dr_mm = 4.0
da_mm = 4.0

[[event]]
time_s = 1.5
flute = 2
kind = "break"
"#;

/// When the flute breaks [s].
pub const BREAK_TIME_S: f64 = 1.5;

/// The trace, written in both forms.
#[derive(Debug, Clone)]
pub struct Trace {
    /// Raw trace CSV.
    pub csv: PathBuf,
    /// TMS1 blob.
    pub blob: PathBuf,
    /// Its sample rate [Hz] (from the blob header).
    pub sample_rate_hz: f32,
    /// Its samples, as the blob holds them.
    pub samples: Vec<Sample>,
}

/// Simulates [`SCENARIO`] into `dir/{name}.csv` and packs it into `dir/{name}.tms1`.
pub fn make_trace(dir: &Path, name: &str) -> Trace {
    std::fs::create_dir_all(dir).expect("create the trace directory");
    let sc = Scenario::from_toml(SCENARIO, "SCENARIO").expect("scenario parses");
    let csv = dir.join(format!("{name}.csv"));
    let f = BufWriter::new(File::create(&csv).expect("create trace CSV"));
    host_sim::sim::write_trace(&sc, f).expect("simulate");
    let blob = dir.join(format!("{name}.tms1"));
    let mut reader = TraceReader::open(&csv).expect("open trace CSV");
    let out = BufWriter::new(File::create(&blob).expect("create blob"));
    write_sample_bin(&mut reader, out).expect("trace-bin");
    let bytes = std::fs::read(&blob).expect("read the blob back");
    let (sample_rate_hz, samples) = decode_samples(&bytes).expect("decode the blob");
    Trace {
        csv,
        blob,
        sample_rate_hz,
        samples,
    }
}

/// One record as the host computes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HostRecord {
    /// `ToothRecord::to_words()`.
    pub words: [u32; RECORD_WORDS],
    /// An alarm is latched after it.
    pub latched: bool,
    /// The event it raised.
    pub event: Option<Cause>,
    /// That event as its telemetry frame carries it: the value, the threshold it crossed
    /// and how many samples before the record's end the output latched.
    pub event_fields: Option<EventFields>,
}

/// The core's pipeline over `samples` with the configuration the firmware runs: the
/// board's default at `sample_rate_hz`.
pub fn host_pipeline(sample_rate_hz: f32, samples: &[Sample]) -> Vec<HostRecord> {
    let mut board = BoardConfig::board_default();
    board.machine.monitor.sample_rate_hz = sample_rate_hz;
    let built = board.build().expect("the board configuration builds");
    let mut st = estimator_core::PipelineState::default();
    samples
        .iter()
        .filter_map(|s| built.pipeline.process(&mut st, s))
        .map(|(r, a)| HostRecord {
            words: r.to_words(),
            latched: a.latched,
            event: a.event.map(|e| e.cause),
            event_fields: a.event.as_ref().map(EventFields::from),
        })
        .collect()
}

/// `host-sim replay --trace csv --bits` with no machine file, as a library call: the
/// records' words.
pub fn host_sim_replay(csv: &Path) -> Vec<[u32; RECORD_WORDS]> {
    let mut reader = TraceReader::open(csv).expect("open trace CSV");
    let rate = reader.detect_sample_rate_hz().expect("read ahead");
    let cfg = load_monitor_config(None, rate)
        .expect("default configuration")
        .config;
    let mut out = Vec::new();
    replay_to(
        &mut reader,
        &cfg,
        &mut out,
        RecordFormat::Bits,
        &ReplayOutputs::default(),
        None,
    )
    .expect("host-sim replay");
    let text = String::from_utf8(out).expect("ASCII lines");
    text.lines()
        .map(|l| {
            let mut w = [0u32; RECORD_WORDS];
            let mut it = l.split_whitespace().skip(1);
            for slot in &mut w {
                let h = it
                    .next()
                    .unwrap_or_else(|| panic!("short --bits line `{l}`"));
                *slot = u32::from_str_radix(h, 16).expect("hex word");
            }
            w
        })
        .collect()
}

/// The byte stream of the frames in a QEMU report (one case line of little-endian words
/// per frame), and the number of lines.
pub fn frames_from_report(stdout: &str) -> (Vec<u8>, usize) {
    let mut bytes = Vec::new();
    let n = target_check::parse_report(stdout, |l| {
        for h in l.split_whitespace().skip(1) {
            let w = u32::from_str_radix(h, 16).unwrap_or_else(|_| panic!("bad word in `{l}`"));
            bytes.extend_from_slice(&w.to_le_bytes());
        }
    })
    .unwrap_or_else(|e| panic!("QEMU report unreadable: {e}\n--- stdout ---\n{stdout}"));
    (bytes, n)
}

/// Decodes a telemetry byte stream.
pub fn decode_frames(bytes: &[u8]) -> (Vec<RecordFrame>, DecodeStats) {
    let mut frames = Vec::new();
    let stats = decode(bytes, |f| frames.push(*f));
    (frames, stats)
}

/// A captured telemetry stream (the UART's raw bytes) into the per-tooth records CSV that
/// `host-sim replay` writes (no truth columns; `time_s` = `end_sample / sample_rate_hz`):
/// `host-sim decode-telemetry`'s own function, [`host_sim::telemetry::decode_to_csv`].
/// Returns what the decoder saw.
pub fn decode_telemetry_to_csv<W: std::io::Write>(
    bytes: &[u8],
    out: W,
) -> anyhow::Result<(DecodeStats, W)> {
    let (summary, w) = host_sim::telemetry::decode_to_csv(bytes, out, None)?;
    Ok((summary.stats, w))
}

/// The `key=value` pairs of the `firmware-qemu stats` line on stderr.
pub fn qemu_stats(stderr: &str) -> BTreeMap<String, u64> {
    let line = stderr
        .lines()
        .find_map(|l| {
            l.trim_end_matches('\r')
                .strip_prefix("firmware-qemu stats ")
        })
        .unwrap_or_else(|| panic!("no stats line\n--- stderr ---\n{stderr}"));
    line.split_whitespace()
        .filter_map(|kv| {
            let (k, v) = kv.split_once('=')?;
            Some((k.to_owned(), v.parse().ok()?))
        })
        .collect()
}
