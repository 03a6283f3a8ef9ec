//! Host-versus-target conformance check for estimator-core.
//!
//! # Design
//!
//! `estimator_core::conformance::run` feeds a fixed grid of inputs through the core and hands
//! back the f32 bit patterns of the outputs. The thumbv7em bin (`src/main.rs`) writes them over
//! semihosting inside QEMU; the host test (`tests/host_vs_target.rs`) computes the same report
//! natively and compares the two line by line. Both sides format through [`write_report`], so
//! a difference can only come from the numbers, never from the formatting.
//!
//! The report is framed, so truncated output (a fault halfway, a timeout) cannot pass as a
//! shorter but matching list:
//!
//! ```text
//! target-check begin
//! 0 3f9e0b2c 40490fdb
//! 1 ...
//! target-check end 8
//! ```
//!
//! Each case line is `"{idx} {bits[0]:08x} {bits[1]:08x} ..."`. On the host, [`host`] also
//! builds the thumbv7em ELF and runs QEMU (optionally with `-icount shift=0` for instruction
//! counts), for reuse by other target tests.
//!
//! Two more thumbv7em programs use the same framing and helpers:
//! - `monitor-replay` ([`write_replay_report`]): the streaming `Monitor` over a raw trace
//!   embedded in flash as a TMS1 blob ([`tms1`]), one case line per tooth record
//!   (`ToothRecord::to_words`), compared by `tests/monitor_replay.rs` with host-sim's replay
//!   of the same trace;
//! - `icount-bench` ([`bench`]): instruction counts of the per-sample and per-tooth work
//!   under `-icount`, run by `tests/icount_bench.rs`.
#![no_std]

#[cfg(not(target_os = "none"))]
extern crate std;

pub mod bench;
#[cfg(not(target_os = "none"))]
pub mod host;
#[cfg(target_os = "none")]
pub mod semihosting;
pub mod tms1;

use estimator_core::monitor::{Monitor, MonitorConfig, MonitorState};
use estimator_core::ConfigError;
use tms1::{Tms1, Tms1Error};

use core::fmt::{self, Write};

/// First line of a report.
pub const BEGIN: &str = "target-check begin";
/// Prefix of the last line of a report; the number of case lines follows it.
pub const END_PREFIX: &str = "target-check end ";

/// Writes one case as a line: its index in decimal, then each output word as 8 hex digits.
pub fn write_case(w: &mut impl Write, idx: u32, bits: &[u32]) -> fmt::Result {
    write!(w, "{idx}")?;
    for b in bits {
        write!(w, " {b:08x}")?;
    }
    w.write_char('\n')
}

/// Runs the whole conformance grid and writes the framed report (see the module docs).
pub fn write_report(w: &mut impl Write) -> fmt::Result {
    writeln!(w, "{BEGIN}")?;
    let mut count: u32 = 0;
    let mut result = Ok(());
    estimator_core::conformance::run(&mut |idx, bits| {
        // The callback cannot return an error: keep the first one and skip the rest.
        if result.is_ok() {
            result = write_case(w, idx, bits);
            count = count.wrapping_add(1);
        }
    });
    result?;
    writeln!(w, "{END_PREFIX}{count}")
}

/// The monitor configuration of a replay: `MonitorConfig::default()` at the trace's sample
/// rate (what `host-sim replay` runs when given no config file).
pub fn replay_config(sample_rate_hz: f32) -> MonitorConfig {
    MonitorConfig {
        sample_rate_hz,
        ..MonitorConfig::default()
    }
}

/// Why a replay could not run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReplayError {
    /// The blob is not a well-formed TMS1 blob.
    Blob(Tms1Error),
    /// The monitor refused its configuration (e.g. a non-positive sample rate).
    Config(ConfigError),
    /// Writing the report failed.
    Write,
}

impl fmt::Display for ReplayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Blob(e) => write!(f, "trace blob: {e}"),
            Self::Config(e) => write!(f, "monitor config: {e}"),
            Self::Write => f.write_str("writing the report failed"),
        }
    }
}

impl From<fmt::Error> for ReplayError {
    fn from(_: fmt::Error) -> Self {
        Self::Write
    }
}

/// Checks `blob` and builds the replay monitor for it.
pub fn replay_monitor(blob: &[u8]) -> Result<(Tms1<'_>, Monitor), ReplayError> {
    let trace = Tms1::parse(blob).map_err(ReplayError::Blob)?;
    let monitor = replay_config(trace.sample_rate_hz())
        .build()
        .map_err(ReplayError::Config)?;
    Ok((trace, monitor))
}

/// Runs the monitor over every sample of `blob` and writes the framed report: one case line
/// per tooth record, `"{record index} {to_words()...}"`. Nothing is written when the blob or
/// the configuration is refused. Returns the number of records.
pub fn write_replay_report(w: &mut impl Write, blob: &[u8]) -> Result<u32, ReplayError> {
    let (trace, monitor) = replay_monitor(blob)?;
    let mut state = MonitorState::default();
    writeln!(w, "{BEGIN}")?;
    let mut count: u32 = 0;
    for s in trace.samples() {
        if let Some(rec) = monitor.process(&mut state, &s) {
            write_case(w, count, &rec.to_words())?;
            count = count.wrapping_add(1);
        }
    }
    writeln!(w, "{END_PREFIX}{count}")?;
    Ok(count)
}

/// Why a report could not be read back.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReportError {
    /// No `BEGIN` line: the program did not start or did not print.
    MissingBegin,
    /// No end line after `BEGIN`: the program stopped halfway.
    MissingEnd,
    /// The end line's count is not a number.
    BadEnd,
    /// The end line's count differs from the number of case lines seen.
    CountMismatch {
        /// Count the program announced.
        announced: usize,
        /// Case lines actually found.
        seen: usize,
    },
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingBegin => write!(f, "no `{BEGIN}` line in the output"),
            Self::MissingEnd => write!(f, "no `{END_PREFIX}N` line: output stops halfway"),
            Self::BadEnd => write!(f, "end line has no valid case count"),
            Self::CountMismatch { announced, seen } => {
                write!(f, "end line announces {announced} cases, {seen} lines seen")
            }
        }
    }
}

/// Extracts the case lines of the first report in `output` (other lines around it, such as
/// QEMU warnings, are ignored). Calls `line` for each case line in order; returns the count.
pub fn parse_report<'a>(
    output: &'a str,
    mut line: impl FnMut(&'a str),
) -> Result<usize, ReportError> {
    // Note: QEMU's stdio may turn "\n" into "\r\n"; `lines()` strips only the "\n".
    let mut lines = output.lines().map(|l| l.trim_end_matches('\r'));
    lines
        .by_ref()
        .find(|l| *l == BEGIN)
        .ok_or(ReportError::MissingBegin)?;
    for (seen, l) in lines.enumerate() {
        if let Some(n) = l.strip_prefix(END_PREFIX) {
            let announced: usize = n.trim().parse().map_err(|_| ReportError::BadEnd)?;
            return if announced == seen {
                Ok(seen)
            } else {
                Err(ReportError::CountMismatch { announced, seen })
            };
        }
        line(l);
    }
    Err(ReportError::MissingEnd)
}
