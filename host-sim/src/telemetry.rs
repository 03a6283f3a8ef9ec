//! `decode-telemetry`: a capture of the board's UART telemetry (the raw bytes, e.g.
//! `cat /dev/ttyUSB0 > capture.bin`) into the per-tooth records CSV that `replay` writes.
//!
//! The frame format and its decoder are the firmware's own ([`firmware::telemetry`], the
//! hardware-free library, built for the host): the records come back bit for bit, with
//! `time_s = end_sample / sample_rate_hz` (the board's sample clock) and no truth columns.
//! What the decoder could not use is counted, never dropped silently: bytes skipped while
//! resynchronising, frames with a bad CRC, frames of another format, frames missing by
//! their sequence numbers, a frame cut off at the end; and the losses the board itself
//! counted (ADC overruns, late or dropped sync edges, frames dropped on a full queue), from
//! the last frame.

use anyhow::{bail, Context, Result};
use firmware::telemetry::{decode, Counters, DecodeStats, RecordFrame};
use std::fmt::Write as _;
use std::io::Write;
use std::path::PathBuf;

use crate::records::RecordWriter;
use crate::replay::ALARM_COLUMNS;
use crate::trace::Truth;

/// Arguments of `host-sim decode-telemetry`.
#[derive(clap::Args, Debug, Clone)]
pub struct DecodeArgs {
    /// Captured telemetry bytes (the UART's output, unmodified).
    #[arg(long, value_name = "FILE")]
    pub input: PathBuf,
    /// Per-tooth records CSV to write; default: standard output.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Alarm events CSV to write (time_s, latched_s, record, tooth, cause, value,
    /// threshold, latched).
    #[arg(long, value_name = "FILE")]
    pub alarms: Option<PathBuf>,
    /// Exit with an error if anything was lost or skipped (bad CRC, sequence gaps,
    /// skipped bytes, a truncated frame, the board's own loss counters).
    #[arg(long)]
    pub strict: bool,
}

/// Shown after `host-sim decode-telemetry --help`.
pub const DECODE_HELP: &str = "\
INPUT: the bytes the board sends on its telemetry UART (PB10, 921 600 baud 8N1), captured as
they come, e.g. `stty -F /dev/ttyUSB0 921600 raw -echo && cat /dev/ttyUSB0 > capture.bin`.
Frame layout: firmware/src/telemetry.rs.

OUTPUT: the per-tooth records CSV of `host-sim replay` (docs/formats.md), one row per frame
decoded, time_s = end_sample / sample rate. On stderr: frames decoded, bytes skipped, bad
CRCs, unsupported frames, frames missing by sequence number, a truncated last frame, and
the board's own loss counters (ADC samples lost, sync edges late or dropped, frames dropped
on a full queue).";

/// What a decode saw.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TelemetrySummary {
    /// The decoder's counts.
    pub stats: DecodeStats,
    /// The board's loss counters in the last frame (they count since start).
    pub counters: Counters,
    /// Records the board produced but did not send (decimation): gaps in the record index
    /// between consecutive frames, frames lost on the wire excluded.
    pub not_sent: u64,
    /// Alarm events in the frames.
    pub alarm_events: u64,
    /// Frames sent while an alarm was latched.
    pub latched_frames: u64,
    /// Bytes read.
    pub bytes: u64,
}

impl TelemetrySummary {
    /// Whether anything was lost or skipped, on the wire or on the board.
    pub fn lossy(&self) -> bool {
        let s = &self.stats;
        let c = &self.counters;
        s.skipped_bytes > 0
            || s.bad_crc > 0
            || s.unsupported > 0
            || s.missing > 0
            || s.truncated
            || c.samples_lost > 0
            || c.edges_late > 0
            || c.edges_dropped > 0
            || c.frames_dropped > 0
    }

    /// A few lines for stderr.
    pub fn report(&self, name: &str) -> String {
        let s = &self.stats;
        let c = &self.counters;
        let mut out = format!(
            "{name}: {} bytes, {} record frames decoded, {} alarm events, {} frames with the \
             alarm latched\n",
            self.bytes, s.frames, self.alarm_events, self.latched_frames
        );
        let _ = writeln!(
            out,
            "  on the wire: {} bytes skipped, {} bad CRC, {} unsupported frames, {} frames \
             missing by sequence number{}",
            s.skipped_bytes,
            s.bad_crc,
            s.unsupported,
            s.missing,
            if s.truncated {
                ", last frame truncated"
            } else {
                ""
            }
        );
        let _ = writeln!(
            out,
            "  on the board (last frame): {} samples lost, {} sync edges late, {} sync edges \
             dropped, {} frames dropped; {} records not sent (decimation)",
            c.samples_lost, c.edges_late, c.edges_dropped, c.frames_dropped, self.not_sent
        );
        if self.lossy() {
            out.push_str("warning: the capture is incomplete (see the counts above)\n");
        }
        out
    }
}

/// One alarm-events row (the format of `replay --alarms`).
fn alarm_row(f: &RecordFrame) -> Option<String> {
    let e = f.alarm.event?;
    let rate = f64::from(f.sample_rate_hz);
    let latched = f.latched_sample().unwrap_or(f.record.end_sample);
    Some(format!(
        "{},{},{},{},{},{},{},{}\n",
        f.record.time_s(f.sample_rate_hz),
        latched as f64 / rate,
        f.index,
        f.record.tooth,
        e.cause.name(),
        e.value,
        e.threshold,
        u8::from(f.alarm.latched)
    ))
}

/// Decodes a captured telemetry stream into the records CSV on `out`; alarm events (with
/// [`ALARM_COLUMNS`]) go to `events` when given. Returns what the decoder saw and the
/// writer, flushed.
pub fn decode_to_csv<W: Write>(
    bytes: &[u8],
    out: W,
    mut events: Option<&mut String>,
) -> Result<(TelemetrySummary, W)> {
    let mut w = RecordWriter::new(out, false)?;
    if let Some(ev) = events.as_deref_mut() {
        ev.push_str(ALARM_COLUMNS);
        ev.push('\n');
    }
    let mut sum = TelemetrySummary {
        bytes: bytes.len() as u64,
        ..TelemetrySummary::default()
    };
    let mut last: Option<(u32, u32)> = None;
    let mut result = Ok(());
    let stats = decode(bytes, |f| {
        if result.is_err() {
            return;
        }
        // Index gaps beyond the frames missing on the wire are records not sent.
        if let Some((seq, index)) = last {
            let frames = u64::from(f.seq.wrapping_sub(seq));
            let records = u64::from(f.index.wrapping_sub(index));
            sum.not_sent += records.saturating_sub(frames);
        }
        last = Some((f.seq, f.index));
        sum.counters = f.counters;
        sum.latched_frames += u64::from(f.alarm.latched);
        if let Some(row) = alarm_row(f) {
            sum.alarm_events += 1;
            if let Some(ev) = events.as_deref_mut() {
                ev.push_str(&row);
            }
        }
        let t = f.record.time_s(f.sample_rate_hz);
        result = w.write(t, &f.record, &Truth::default());
    });
    result?;
    sum.stats = stats;
    Ok((sum, w.finish()?))
}

/// The `decode-telemetry` command: the report goes to stderr.
pub fn run(args: &DecodeArgs) -> Result<TelemetrySummary> {
    let name = args.input.display().to_string();
    let bytes = std::fs::read(&args.input).with_context(|| format!("cannot read {name}"))?;
    let mut events = String::new();
    let want_events = args.alarms.is_some();
    let ev = want_events.then_some(&mut events);
    let no_frames = |s: &TelemetrySummary| -> Result<()> {
        if s.stats.frames == 0 && !bytes.is_empty() {
            eprint!("{}", s.report(&name));
            bail!("{name}: no telemetry frame found in {} bytes", bytes.len());
        }
        Ok(())
    };
    let summary = match &args.output {
        // No output file for a capture without a frame (the wrong file, the wrong baud rate).
        Some(p) => crate::demo::write_then_rename(p, |w| {
            let s = decode_to_csv(&bytes, w, ev)?.0;
            no_frames(&s)?;
            Ok(s)
        })?,
        None => {
            let out = std::io::BufWriter::new(std::io::stdout().lock());
            let (s, mut w) = decode_to_csv(&bytes, out, ev)?;
            w.flush().context("writing the records")?;
            no_frames(&s)?;
            s
        }
    };
    eprint!("{}", summary.report(&name));
    if let Some(path) = &args.alarms {
        crate::demo::write_then_rename(path, |w| {
            w.write_all(events.as_bytes())
                .with_context(|| format!("cannot write {}", path.display()))
        })?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(p) = &args.output {
        eprintln!("wrote {}", p.display());
    }
    if args.strict && summary.lossy() {
        bail!("{name}: the capture is incomplete (--strict)");
    }
    Ok(summary)
}
