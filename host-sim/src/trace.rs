//! The raw trace: one row per ADC sample, what the board sees plus, from a simulator, the
//! ground truth. Format: docs/formats.md ("Raw trace CSV").
//!
//! This file fixes the row type and the column names; the streaming reader and writer
//! live beside them.
//!
//! # Design
//! - [`TraceReader`] streams a file a line at a time (one reused buffer, no allocation per
//!   row): `#` comment lines and `# key = value` metadata, then the header, then rows. The
//!   header says what the file carries ([`TraceKind`]); columns it does not know are
//!   ignored. Only the file's structure is an error (a missing column, a row with the wrong
//!   number of fields, an empty field, text where a number belongs), named by file, line
//!   and column. NaN and inf are numbers: they pass through to the Monitor, which flags the
//!   tooth period (`input_fault`), as the board does with a bad ADC reading.
//! - [`TraceWriter`] writes what the reader reads, f32 values in Rust's shortest round-trip
//!   form (`{}`) and the time as an f64 the same way: write -> read is bit-exact.
//! - The fast path is hand-rolled (split on `,`, `str::parse`), not the `csv` crate: replay
//!   speed is parse speed (BENCHMARKS.md, "Replay throughput"). No quoting: a raw trace is
//!   all numbers.
//! - [`encode_samples`] packs samples for the QEMU image (format in docs/formats.md).
//!
//! [`RowSource`] is what replay reads: this reader, or a converted recording
//! ([`crate::kistler::KistlerReader`]).

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::drive::SpindleModel;
use estimator_core::monitor::Input;
use estimator_core::Sample;
use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;

/// One sample of a raw trace.
///
/// Input channels follow [`estimator_core::Sample`]; which of `feed_x_a`/`fx_n` and
/// `spindle_a`/`spindle_load_pct` a file carries is told by its header.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TraceRow {
    /// Time since the start of the trace [s].
    pub time_s: f64,
    /// Tooth-sync (or revolution) pulse at this sample.
    pub sync: bool,
    /// Feed-axis currents X, Y [A] (motor route) or feed-frame forces `F_ax`, `F_ay` [N]
    /// (dynamometer route).
    pub feed: [f32; 2],
    /// Feed velocity X, Y [mm/min]; NaN when the file has no velocity columns.
    pub feed_velocity_mm_min: [f32; 2],
    /// Spindle current [A] or spindle load [%].
    pub spindle: f32,
    /// Ground truth, NaN where unknown.
    pub truth: Truth,
}

/// Ground truth carried by simulated traces (`true_*` columns).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Radial depth of cut [mm].
    pub dr_mm: f32,
    /// Axial depth of cut [mm].
    pub da_mm: f32,
    /// Feed per tooth [mm/tooth].
    pub tc_mm: f32,
    /// Spindle speed [rpm].
    pub rpm: f32,
    /// Bit i set while flute i is intact (0xff.. for an unknown count: all set).
    pub flutes_intact: u32,
    /// Feed-frame forces on the tool, feed direction and normal [N].
    pub fx_n: f32,
    /// Normal to the feed [N].
    pub fy_n: f32,
    /// Tangential force (spindle torque / R) [N].
    pub ft_n: f32,
}

impl Default for Truth {
    fn default() -> Self {
        Truth {
            dr_mm: f32::NAN,
            da_mm: f32::NAN,
            tc_mm: f32::NAN,
            rpm: f32::NAN,
            flutes_intact: u32::MAX,
            fx_n: f32::NAN,
            fy_n: f32::NAN,
            ft_n: f32::NAN,
        }
    }
}

/// Column names, in the order the writer emits them.
pub mod columns {
    /// Time [s].
    pub const TIME: &str = "time_s";
    /// Sync pulse, 0 or 1.
    pub const SYNC: &str = "sync";
    /// Feed-axis currents [A].
    pub const FEED_X_A: &str = "feed_x_a";
    /// Second feed axis [A] (optional).
    pub const FEED_Y_A: &str = "feed_y_a";
    /// Feed-frame forces [N] (dynamometer route, instead of the currents).
    pub const FX_N: &str = "fx_n";
    /// Normal force [N] (dynamometer route).
    pub const FY_N: &str = "fy_n";
    /// Feed velocities [mm/min] (optional: the config's nominal feed otherwise).
    pub const FEED_VX: &str = "feed_vx_mm_min";
    /// Second axis velocity.
    pub const FEED_VY: &str = "feed_vy_mm_min";
    /// Spindle current [A].
    pub const SPINDLE_A: &str = "spindle_a";
    /// Spindle load [%] (paper 003), instead of the current.
    pub const SPINDLE_LOAD: &str = "spindle_load_pct";
    /// Ground truth columns.
    pub const TRUE_DR: &str = "true_dr_mm";
    /// Truth: axial depth.
    pub const TRUE_DA: &str = "true_da_mm";
    /// Truth: feed per tooth.
    pub const TRUE_TC: &str = "true_tc_mm";
    /// Truth: spindle speed.
    pub const TRUE_RPM: &str = "true_rpm";
    /// Truth: intact-flute bitmask (decimal integer).
    pub const TRUE_FLUTES: &str = "true_flutes_intact";
    /// Truth: feed force.
    pub const TRUE_FX: &str = "true_fx_n";
    /// Truth: normal force.
    pub const TRUE_FY: &str = "true_fy_n";
    /// Truth: tangential force.
    pub const TRUE_FT: &str = "true_ft_n";
}

impl TraceRow {
    /// The Monitor's input for this row.
    ///
    /// Channels the file does not carry come out as the reader filled them: a missing
    /// second feed axis or spindle column as 0, missing velocity columns as NaN. NaN
    /// velocities make every tooth period an `input_fault` unless the Monitor ignores them,
    /// so a trace without velocity columns must be replayed with a config that has
    /// `FeedVelocity::Nominal` (`feed_velocity = { nominal = [vx, vy] }`); replay refuses
    /// to start otherwise.
    pub fn to_sample(&self) -> Sample {
        Sample {
            feed: self.feed,
            feed_velocity_mm_min: self.feed_velocity_mm_min,
            spindle: self.spindle,
            sync: self.sync,
        }
    }
}

/// What the feed channels of a trace carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeedSignal {
    /// Feed-axis motor currents `feed_x_a` (and `feed_y_a`) [A]: the motor route.
    Current,
    /// Feed-frame forces `fx_n`, `fy_n` [N] from a dynamometer.
    Force,
}

/// What the spindle channel of a trace carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpindleSignal {
    /// `spindle_a` [A].
    Current,
    /// `spindle_load_pct` [%].
    Load,
    /// No spindle column (dynamometer traces only); rows carry 0.
    None,
}

/// Which columns a trace has: the reader tells it from the header, the writer is told.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceKind {
    /// Currents or forces.
    pub feed: FeedSignal,
    /// A second feed axis (`feed_y_a`, `feed_vy_mm_min`). Always true for
    /// [`FeedSignal::Force`], whose `fy_n` is the force normal to the feed.
    pub two_axis: bool,
    /// Feed velocity columns (`feed_vx_mm_min`, and `feed_vy_mm_min` when two-axis).
    pub has_velocity: bool,
    /// Spindle column.
    pub spindle: SpindleSignal,
    /// The `true_*` columns (all eight when writing; any subset is read).
    pub has_truth: bool,
}

impl TraceKind {
    /// The columns of a trace of the board's `input`: currents or forces, a second feed
    /// axis if the drive has one (always for forces: `fy_n`), the spindle signal its model
    /// reads. The simulators write what a replay with the same `input` reads.
    pub fn for_input(input: &Input, has_velocity: bool, has_truth: bool) -> TraceKind {
        let (feed, two_axis, spindle) = match input {
            Input::Motor {
                feed,
                spindle: SpindleModel::Current { .. },
            } => (FeedSignal::Current, feed.two_axis, SpindleSignal::Current),
            Input::Motor {
                feed,
                spindle: SpindleModel::Load { .. },
            } => (FeedSignal::Current, feed.two_axis, SpindleSignal::Load),
            Input::Dynamometer => (FeedSignal::Force, true, SpindleSignal::None),
        };
        TraceKind {
            feed,
            two_axis,
            has_velocity,
            spindle,
            has_truth,
        }
    }

    /// Checks the combination: a motor-current trace needs a spindle column (the motor
    /// route's second force), a force trace both forces.
    pub fn validate(&self) -> Result<()> {
        match (self.feed, self.two_axis, self.spindle) {
            (FeedSignal::Force, false, _) => bail!(
                "a dynamometer trace carries both `{}` and `{}`: set two_axis",
                columns::FX_N,
                columns::FY_N
            ),
            (FeedSignal::Current, _, SpindleSignal::None) => bail!(
                "a motor-current trace needs a spindle column (`{}` or `{}`)",
                columns::SPINDLE_A,
                columns::SPINDLE_LOAD
            ),
            _ => Ok(()),
        }
    }

    /// Column names in the order [`TraceWriter`] writes them.
    pub fn columns(&self) -> Vec<&'static str> {
        use columns::*;
        let mut c = vec![TIME, SYNC];
        match self.feed {
            FeedSignal::Current => {
                c.push(FEED_X_A);
                if self.two_axis {
                    c.push(FEED_Y_A);
                }
            }
            FeedSignal::Force => c.extend([FX_N, FY_N]),
        }
        if self.has_velocity {
            c.push(FEED_VX);
            if self.two_axis {
                c.push(FEED_VY);
            }
        }
        match self.spindle {
            SpindleSignal::Current => c.push(SPINDLE_A),
            SpindleSignal::Load => c.push(SPINDLE_LOAD),
            SpindleSignal::None => {}
        }
        if self.has_truth {
            c.extend(TRUTH);
        }
        c
    }
}

/// The truth columns, in writer order (the order of [`Truth`]'s fields).
const TRUTH: [&str; 8] = [
    columns::TRUE_DR,
    columns::TRUE_DA,
    columns::TRUE_TC,
    columns::TRUE_RPM,
    columns::TRUE_FLUTES,
    columns::TRUE_FX,
    columns::TRUE_FY,
    columns::TRUE_FT,
];

/// Metadata key of the sample rate in a `# key = value` comment.
pub const SAMPLE_RATE_KEY: &str = "sample_rate_hz";

/// What replay reads: a stream of rows with its kind and sample rate.
///
/// Implemented by [`TraceReader`] (raw trace CSV) and [`crate::kistler::KistlerReader`]
/// (a dynamometer export converted on the fly).
pub trait RowSource {
    /// The file, for messages.
    fn name(&self) -> &str;
    /// Which channels the rows carry.
    fn kind(&self) -> TraceKind;
    /// The sample rate [Hz] as far as known without reading further.
    fn sample_rate_hz(&self) -> Option<f64>;
    /// The sample rate [Hz], reading ahead (rows read ahead are still returned by
    /// `next_row`). `None`: the source cannot tell (no metadata and fewer than two rows).
    fn detect_sample_rate_hz(&mut self) -> Result<Option<f64>>;
    /// The next row; `None` at the end.
    fn next_row(&mut self) -> Result<Option<TraceRow>>;
    /// Bytes of the file consumed so far (for a progress bar).
    fn bytes_read(&self) -> u64;
}

/// Where each known column sits in a row.
#[derive(Clone, Copy, Debug, Default)]
struct Layout {
    time: usize,
    sync: usize,
    feed: [Option<usize>; 2],
    velocity: [Option<usize>; 2],
    spindle: Option<usize>,
    /// In [`TRUTH`] order.
    truth: [Option<usize>; 8],
    /// Fields per row (the header's).
    fields: usize,
}

/// What the header fixed: where the columns are, what they are called, the file's name.
struct Schema {
    name: String,
    kind: TraceKind,
    layout: Layout,
    /// Column names of the feed and spindle channels, for messages.
    feed_names: [&'static str; 2],
    spindle_name: &'static str,
}

/// Streaming reader of the raw trace CSV (docs/formats.md, "Raw trace CSV").
pub struct TraceReader<R: BufRead> {
    r: R,
    schema: Schema,
    metadata: Vec<(String, String)>,
    metadata_rate: Option<f64>,
    /// Time stamps of the first two rows, once read.
    first_times: [Option<f64>; 2],
    /// Number of the line last read (1-based).
    line: u64,
    bytes: u64,
    /// A line copied out of the reader (header, comments, a line across a buffer refill).
    buf: Vec<u8>,
    spans: Vec<(usize, usize)>,
    /// Rows read ahead by `detect_sample_rate_hz`.
    ahead: VecDeque<TraceRow>,
}

impl TraceReader<BufReader<File>> {
    /// Opens `path` and reads its metadata and header.
    pub fn open(path: &Path) -> Result<TraceReader<BufReader<File>>> {
        let name = path.display().to_string();
        let f = File::open(path).with_context(|| format!("cannot open {name}"))?;
        TraceReader::new(BufReader::with_capacity(1 << 16, f), &name)
    }
}

impl<R: BufRead> TraceReader<R> {
    /// Reads the comment lines (`# key = value` metadata, e.g. `# sample_rate_hz = 10000`)
    /// and the header. `name` names the input in messages. Errors: no header, a missing
    /// required column (all of them are named), a column given twice, two alternatives
    /// given together (`feed_x_a` and `fx_n`), an unreadable sample rate.
    pub fn new(r: R, name: &str) -> Result<Self> {
        let mut rd = TraceReader {
            r,
            schema: Schema {
                name: name.to_string(),
                kind: TraceKind {
                    feed: FeedSignal::Current,
                    two_axis: false,
                    has_velocity: false,
                    spindle: SpindleSignal::None,
                    has_truth: false,
                },
                layout: Layout::default(),
                feed_names: [columns::FEED_X_A, columns::FEED_Y_A],
                spindle_name: columns::SPINDLE_A,
            },
            metadata: Vec::new(),
            metadata_rate: None,
            first_times: [None; 2],
            line: 0,
            bytes: 0,
            buf: Vec::with_capacity(256),
            spans: Vec::with_capacity(32),
            ahead: VecDeque::new(),
        };
        loop {
            if !rd.read_line()? {
                bail!("{name}: no header line (empty file?); docs/formats.md, \"Raw trace CSV\"");
            }
            let text = rd.line_text()?.trim();
            if text.is_empty() {
                continue;
            }
            if let Some(comment) = text.strip_prefix('#') {
                if let Some((k, v)) = comment.split_once('=') {
                    let (k, v) = (k.trim().to_string(), v.trim().to_string());
                    if k == SAMPLE_RATE_KEY {
                        let rate = v.parse::<f64>().ok().filter(|r| r.is_finite() && *r > 0.0);
                        let Some(rate) = rate else {
                            bail!(
                                "{name} line {}: {SAMPLE_RATE_KEY} `{v}` is not a positive number",
                                rd.line
                            );
                        };
                        rd.metadata_rate = Some(rate);
                    }
                    rd.metadata.push((k, v));
                }
                continue;
            }
            let header: Vec<String> = text.split(',').map(|h| h.trim().to_string()).collect();
            rd.parse_header(&header)?;
            return Ok(rd);
        }
    }

    fn parse_header(&mut self, header: &[String]) -> Result<()> {
        use columns::*;
        let (name, line) = (self.schema.name.clone(), self.line);
        for (i, h) in header.iter().enumerate() {
            if header[..i].contains(h) && !h.is_empty() {
                bail!("{name} line {line}: column `{h}` appears twice");
            }
        }
        let find = |c: &str| header.iter().position(|h| h == c);
        let mut missing: Vec<String> = Vec::new();
        let mut need = |c: &str, why: &str| {
            let at = find(c);
            if at.is_none() {
                missing.push(format!("`{c}` ({why})"));
            }
            at.unwrap_or(0)
        };
        let time = need(TIME, "sample time, s");
        let sync = need(SYNC, "tooth-sync pulse, 0 or 1");
        let both = |a: &str, b: &str| -> Result<()> {
            if find(a).is_some() && find(b).is_some() {
                bail!("{name} line {line}: both `{a}` and `{b}`; a trace carries one of them");
            }
            Ok(())
        };
        both(FEED_X_A, FX_N)?;
        both(SPINDLE_A, SPINDLE_LOAD)?;
        let (feed, feed_names) = if find(FX_N).is_some() {
            (FeedSignal::Force, [FX_N, FY_N])
        } else {
            (FeedSignal::Current, [FEED_X_A, FEED_Y_A])
        };
        let feed0 = match feed {
            FeedSignal::Force => Some(need(FX_N, "feed force, N")),
            FeedSignal::Current => Some(need(
                FEED_X_A,
                "feed X motor current, A; or fx_n for a dynamometer trace",
            )),
        };
        let feed1 = match feed {
            FeedSignal::Force => Some(need(FY_N, "force normal to the feed, N")),
            FeedSignal::Current => find(FEED_Y_A),
        };
        if feed == FeedSignal::Force && find(FEED_Y_A).is_some() {
            bail!("{name} line {line}: `{FEED_Y_A}` in a force trace (`{FX_N}`, `{FY_N}`)");
        }
        let two_axis = feed1.is_some();
        let vx = find(FEED_VX);
        let vy = find(FEED_VY);
        if vx.is_none() && vy.is_some() {
            missing.push(format!("`{FEED_VX}` (given `{FEED_VY}`)"));
        }
        if vx.is_some() && vy.is_none() && feed == FeedSignal::Current && two_axis {
            missing.push(format!("`{FEED_VY}` (two-axis feed with velocities)"));
        }
        let (spindle, spindle_at, spindle_name) = match (find(SPINDLE_A), find(SPINDLE_LOAD)) {
            (Some(i), _) => (SpindleSignal::Current, Some(i), SPINDLE_A),
            (None, Some(i)) => (SpindleSignal::Load, Some(i), SPINDLE_LOAD),
            (None, None) => (SpindleSignal::None, None, SPINDLE_A),
        };
        if feed == FeedSignal::Current && spindle == SpindleSignal::None {
            missing.push(format!(
                "`{SPINDLE_A}` or `{SPINDLE_LOAD}` (spindle signal of the motor route)"
            ));
        }
        if !missing.is_empty() {
            bail!(
                "{name} line {line}: missing column{} {}; docs/formats.md, \"Raw trace CSV\"",
                if missing.len() > 1 { "s" } else { "" },
                missing.join(", ")
            );
        }
        let truth = TRUTH.map(find);
        self.schema.layout = Layout {
            time,
            sync,
            feed: [feed0, feed1],
            velocity: [vx, vy],
            spindle: spindle_at,
            truth,
            fields: header.len(),
        };
        self.schema.feed_names = feed_names;
        self.schema.spindle_name = spindle_name;
        self.schema.kind = TraceKind {
            feed,
            two_axis,
            has_velocity: vx.is_some(),
            spindle,
            has_truth: truth.iter().any(Option::is_some),
        };
        Ok(())
    }

    /// Reads one line into `buf` without its line end; false at the end of the input.
    fn read_line(&mut self) -> Result<bool> {
        self.buf.clear();
        let n = self.r.read_until(b'\n', &mut self.buf).with_context(|| {
            format!("{}: cannot read after line {}", self.schema.name, self.line)
        })?;
        if n == 0 {
            return Ok(false);
        }
        self.bytes += n as u64;
        self.line += 1;
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
        }
        if self.buf.last() == Some(&b'\r') {
            self.buf.pop();
        }
        Ok(true)
    }

    fn line_text(&self) -> Result<&str> {
        std::str::from_utf8(&self.buf)
            .map_err(|_| anyhow!("{} line {}: not UTF-8 text", self.schema.name, self.line))
    }

    /// The next data row, parsed in place in the reader's buffer when the whole line is
    /// there (no copy), else copied out first.
    fn read_row(&mut self) -> Result<Option<TraceRow>> {
        loop {
            let avail = match self.r.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    return Err(anyhow!(
                        "{}: cannot read after line {}: {e}",
                        self.schema.name,
                        self.line
                    ))
                }
            };
            if avail.is_empty() {
                return Ok(None);
            }
            // One pass finds the line end and the commas before it.
            self.spans.clear();
            let mut start = 0;
            let mut end = None;
            for (i, &b) in avail.iter().enumerate() {
                if b == b',' {
                    self.spans.push((start, i));
                    start = i + 1;
                } else if b == b'\n' {
                    end = Some(i);
                    break;
                }
            }
            let Some(nl) = end else {
                // The line runs past the buffer, or the file ends without a newline.
                if !self.read_line()? {
                    return Ok(None);
                }
                if self.buf.is_empty() {
                    continue;
                }
                let row = parse_line(&self.schema, &mut self.spans, self.line, &self.buf)?;
                return Ok(Some(self.note_time(row)));
            };
            let mut line = &avail[..nl];
            if line.last() == Some(&b'\r') {
                line = &line[..line.len() - 1];
            }
            self.spans.push((start, line.len()));
            self.line += 1;
            self.bytes += nl as u64 + 1;
            let parsed = if line.is_empty() {
                None
            } else {
                Some(parse_split(&self.schema, &self.spans, self.line, line))
            };
            self.r.consume(nl + 1);
            if let Some(row) = parsed {
                return Ok(Some(self.note_time(row?)));
            }
        }
    }

    /// Keeps the first two time stamps (for the sample rate).
    fn note_time(&mut self, row: TraceRow) -> TraceRow {
        for slot in &mut self.first_times {
            if slot.is_none() {
                *slot = Some(row.time_s);
                break;
            }
        }
        row
    }

    /// Which columns the file carries.
    pub fn kind(&self) -> TraceKind {
        self.schema.kind
    }

    /// The file's name as given.
    pub fn name(&self) -> &str {
        &self.schema.name
    }

    /// Every `# key = value` comment before the header, in order.
    pub fn metadata(&self) -> &[(String, String)] {
        &self.metadata
    }

    /// Sample rate [Hz]: the `# sample_rate_hz = ...` metadata if the file has it, else
    /// `1 / (t1 - t0)` from the first two time stamps once they have been read (by
    /// [`Self::next_row`] or [`Self::detect_sample_rate_hz`]), rounded to a millihertz
    /// (time stamps are decimal text: `2.0001 - 2.0` is not exactly `1e-4`). `None` before
    /// that, or if the two stamps do not increase.
    pub fn sample_rate_hz(&self) -> Option<f64> {
        self.metadata_rate.or_else(|| match self.first_times {
            [Some(t0), Some(t1)] => rate_from_times(t0, t1),
            _ => None,
        })
    }

    /// [`Self::sample_rate_hz`], reading up to two rows ahead if the file has no metadata
    /// (those rows still come out of [`Self::next_row`]).
    pub fn detect_sample_rate_hz(&mut self) -> Result<Option<f64>> {
        while self.sample_rate_hz().is_none() && self.first_times[1].is_none() {
            match self.read_row()? {
                Some(row) => self.ahead.push_back(row),
                None => break,
            }
        }
        Ok(self.sample_rate_hz())
    }

    /// The next row, `None` at the end. Errors name the file, the line and the column.
    pub fn next_row(&mut self) -> Result<Option<TraceRow>> {
        if let Some(row) = self.ahead.pop_front() {
            return Ok(Some(row));
        }
        self.read_row()
    }

    /// Number of the line last read (1-based; comments and the header count).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// Bytes read so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes
    }
}

impl<R: BufRead> RowSource for TraceReader<R> {
    fn name(&self) -> &str {
        TraceReader::name(self)
    }
    fn kind(&self) -> TraceKind {
        TraceReader::kind(self)
    }
    fn sample_rate_hz(&self) -> Option<f64> {
        TraceReader::sample_rate_hz(self)
    }
    fn detect_sample_rate_hz(&mut self) -> Result<Option<f64>> {
        TraceReader::detect_sample_rate_hz(self)
    }
    fn next_row(&mut self) -> Result<Option<TraceRow>> {
        TraceReader::next_row(self)
    }
    fn bytes_read(&self) -> u64 {
        TraceReader::bytes_read(self)
    }
}

/// Parses one data line (without its line end).
fn parse_line(
    schema: &Schema,
    spans: &mut Vec<(usize, usize)>,
    line: u64,
    bytes: &[u8],
) -> Result<TraceRow> {
    spans.clear();
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b',' {
            spans.push((start, i));
            start = i + 1;
        }
    }
    spans.push((start, bytes.len()));
    parse_split(schema, spans, line, bytes)
}

/// Parses one data line already split at its commas (`spans`).
#[inline]
fn parse_split(
    schema: &Schema,
    spans: &[(usize, usize)],
    line: u64,
    bytes: &[u8],
) -> Result<TraceRow> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| anyhow!("{} line {line}: not UTF-8 text", schema.name))?;
    if spans.len() != schema.layout.fields {
        bail!(
            "{} line {line}: {} fields, the header has {}",
            schema.name,
            spans.len(),
            schema.layout.fields
        );
    }
    Row {
        schema,
        line,
        text,
        spans,
    }
    .parse()
}

/// `s` without surrounding white space; the common case (none) costs two compares.
#[inline]
fn trim_fast(s: &str) -> &str {
    let b = s.as_bytes();
    match (b.first(), b.last()) {
        (Some(f), Some(l)) if !f.is_ascii_whitespace() && !l.is_ascii_whitespace() => s,
        _ => s.trim(),
    }
}

/// One data line split into fields.
struct Row<'a> {
    schema: &'a Schema,
    line: u64,
    text: &'a str,
    spans: &'a [(usize, usize)],
}

impl Row<'_> {
    /// The trimmed text of field `idx`.
    #[inline]
    fn field(&self, idx: usize) -> &str {
        let (a, b) = self.spans.get(idx).copied().unwrap_or((0, 0));
        trim_fast(self.text.get(a..b).unwrap_or_default())
    }

    fn bad_value(&self, idx: usize, col: &str, what: &str) -> anyhow::Error {
        let (name, line) = (&self.schema.name, self.line);
        let text = self.field(idx);
        if text.is_empty() {
            anyhow!("{name} line {line}, column `{col}`: empty value (write NaN for a missing one)")
        } else {
            anyhow!("{name} line {line}, column `{col}`: `{text}` is not {what}")
        }
    }

    #[inline]
    fn f32_at(&self, idx: usize, col: &str) -> Result<f32> {
        self.field(idx)
            .parse::<f32>()
            .map_err(|_| self.bad_value(idx, col, "a number"))
    }

    fn parse(&self) -> Result<TraceRow> {
        let lay = &self.schema.layout;
        let time_s = self
            .field(lay.time)
            .parse::<f64>()
            .map_err(|_| self.bad_value(lay.time, columns::TIME, "a number"))?;
        let sync = match self.field(lay.sync) {
            "1" => true,
            "0" => false,
            _ => return Err(self.bad_value(lay.sync, columns::SYNC, "0 or 1")),
        };
        let mut row = TraceRow {
            time_s,
            sync,
            feed: [0.0; 2],
            feed_velocity_mm_min: [f32::NAN; 2],
            spindle: 0.0,
            truth: Truth::default(),
        };
        for k in 0..2 {
            if let Some(i) = lay.feed[k] {
                row.feed[k] = self.f32_at(i, self.schema.feed_names[k])?;
            }
        }
        if let Some(i) = lay.velocity[0] {
            row.feed_velocity_mm_min[0] = self.f32_at(i, columns::FEED_VX)?;
            row.feed_velocity_mm_min[1] = match lay.velocity[1] {
                Some(j) => self.f32_at(j, columns::FEED_VY)?,
                None => 0.0,
            };
        }
        if let Some(i) = lay.spindle {
            row.spindle = self.f32_at(i, self.schema.spindle_name)?;
        }
        if self.schema.kind.has_truth {
            self.truth(&mut row.truth)?;
        }
        Ok(row)
    }

    fn truth(&self, t: &mut Truth) -> Result<()> {
        let lay = &self.schema.layout;
        let get = |k: usize| -> Result<Option<f32>> {
            lay.truth[k].map(|i| self.f32_at(i, TRUTH[k])).transpose()
        };
        if let Some(v) = get(0)? {
            t.dr_mm = v;
        }
        if let Some(v) = get(1)? {
            t.da_mm = v;
        }
        if let Some(v) = get(2)? {
            t.tc_mm = v;
        }
        if let Some(v) = get(3)? {
            t.rpm = v;
        }
        if let Some(i) = lay.truth[4] {
            t.flutes_intact = self
                .field(i)
                .parse::<u32>()
                .map_err(|_| self.bad_value(i, TRUTH[4], "a bitmask (decimal integer)"))?;
        }
        if let Some(v) = get(5)? {
            t.fx_n = v;
        }
        if let Some(v) = get(6)? {
            t.fy_n = v;
        }
        if let Some(v) = get(7)? {
            t.ft_n = v;
        }
        Ok(())
    }
}

/// `1 / (t1 - t0)` rounded to a millihertz; `None` unless the stamps increase.
pub fn rate_from_times(t0: f64, t1: f64) -> Option<f64> {
    let dt = t1 - t0;
    if !(dt.is_finite() && dt > 0.0) {
        return None;
    }
    Some((1e3 / dt).round() / 1e3)
}

/// Streaming writer of the raw trace CSV: the reader's format, bit-exact on the way back.
///
/// Writes a line per call: give it a `BufWriter` for a file.
pub struct TraceWriter<W: Write> {
    w: W,
    kind: TraceKind,
    line: String,
}

impl<W: Write> TraceWriter<W> {
    /// Writes the metadata comments (`# sample_rate_hz = ...`) and the header for `kind`
    /// (columns in [`TraceKind::columns`] order; the eight truth columns iff
    /// `kind.has_truth`).
    pub fn new(mut w: W, kind: TraceKind, sample_rate_hz: f64) -> Result<Self> {
        kind.validate()?;
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            bail!("sample rate {sample_rate_hz} Hz is not a positive number");
        }
        let head = format!(
            "# raw trace (docs/formats.md, \"Raw trace CSV\")\n# {SAMPLE_RATE_KEY} = {sample_rate_hz}\n{}\n",
            kind.columns().join(",")
        );
        w.write_all(head.as_bytes())
            .context("writing the trace header")?;
        Ok(TraceWriter {
            w,
            kind,
            line: String::with_capacity(256),
        })
    }

    /// The columns being written.
    pub fn kind(&self) -> TraceKind {
        self.kind
    }

    /// Writes one row: the columns of the kind, other fields of `row` ignored. f32 and f64
    /// values in shortest round-trip form (NaN as `NaN`, infinities as `inf`/`-inf`).
    pub fn write_row(&mut self, row: &TraceRow) -> Result<()> {
        use std::fmt::Write as _;
        let k = self.kind;
        let l = &mut self.line;
        l.clear();
        // Writing to a String cannot fail.
        let _ = write!(l, "{},{}", row.time_s, u8::from(row.sync));
        let _ = write!(l, ",{}", row.feed[0]);
        if k.two_axis {
            let _ = write!(l, ",{}", row.feed[1]);
        }
        if k.has_velocity {
            let _ = write!(l, ",{}", row.feed_velocity_mm_min[0]);
            if k.two_axis {
                let _ = write!(l, ",{}", row.feed_velocity_mm_min[1]);
            }
        }
        if k.spindle != SpindleSignal::None {
            let _ = write!(l, ",{}", row.spindle);
        }
        if k.has_truth {
            let t = &row.truth;
            let _ = write!(
                l,
                ",{},{},{},{},{},{},{},{}",
                t.dr_mm, t.da_mm, t.tc_mm, t.rpm, t.flutes_intact, t.fx_n, t.fy_n, t.ft_n
            );
        }
        l.push('\n');
        self.w.write_all(l.as_bytes()).context("writing the trace")
    }

    /// Flushes and hands back the writer.
    pub fn finish(mut self) -> Result<W> {
        self.w.flush().context("writing the trace")?;
        Ok(self.w)
    }
}

// ---------------------------------------------------------------------------------------
// Binary samples for the QEMU image
// ---------------------------------------------------------------------------------------

/// First four bytes of the binary sample format.
pub const SAMPLE_BIN_MAGIC: [u8; 4] = *b"TMS1";
/// Bytes before the first sample: magic, f32 sample rate, u32 count.
pub const SAMPLE_BIN_HEADER_BYTES: usize = 12;
/// Bytes per sample: six f32.
pub const SAMPLE_BIN_SAMPLE_BYTES: usize = 24;

/// Packs samples for the QEMU image, little-endian: magic `TMS1`, f32 sample rate [Hz],
/// u32 count, then per sample six f32: `feed[0]`, `feed[1]`, `feed_velocity[0]`,
/// `feed_velocity[1]`, `spindle`, `sync` (0.0 or 1.0). Errors past `u32::MAX` samples.
pub fn encode_samples(sample_rate_hz: f32, samples: &[Sample]) -> Result<Vec<u8>> {
    let count = u32::try_from(samples.len())
        .map_err(|_| anyhow!("{} samples: more than a u32 counts", samples.len()))?;
    let mut out =
        Vec::with_capacity(SAMPLE_BIN_HEADER_BYTES + SAMPLE_BIN_SAMPLE_BYTES * samples.len());
    out.extend_from_slice(&SAMPLE_BIN_MAGIC);
    out.extend_from_slice(&sample_rate_hz.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    for s in samples {
        let sync = if s.sync { 1.0f32 } else { 0.0 };
        for v in [
            s.feed[0],
            s.feed[1],
            s.feed_velocity_mm_min[0],
            s.feed_velocity_mm_min[1],
            s.spindle,
            sync,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(out)
}

/// Inverse of [`encode_samples`]: the sample rate and the samples. Errors on a wrong magic
/// or a length that does not match the count.
pub fn decode_samples(bytes: &[u8]) -> Result<(f32, Vec<Sample>)> {
    let word = |at: usize| -> [u8; 4] {
        let mut w = [0u8; 4];
        if let Some(b) = bytes.get(at..at + 4) {
            w.copy_from_slice(b);
        }
        w
    };
    if bytes.len() < SAMPLE_BIN_HEADER_BYTES || word(0) != SAMPLE_BIN_MAGIC {
        bail!("not a sample file: no `TMS1` header");
    }
    let rate = f32::from_le_bytes(word(4));
    let count = u32::from_le_bytes(word(8)) as usize;
    let want = SAMPLE_BIN_HEADER_BYTES + SAMPLE_BIN_SAMPLE_BYTES * count;
    if bytes.len() != want {
        bail!(
            "sample file of {} bytes, its count ({count}) needs {want}",
            bytes.len()
        );
    }
    let samples = (0..count)
        .map(|i| {
            let at = SAMPLE_BIN_HEADER_BYTES + SAMPLE_BIN_SAMPLE_BYTES * i;
            let f = |k: usize| f32::from_le_bytes(word(at + 4 * k));
            Sample {
                feed: [f(0), f(1)],
                feed_velocity_mm_min: [f(2), f(3)],
                spindle: f(4),
                sync: f(5) != 0.0,
            }
        })
        .collect();
    Ok((rate, samples))
}

/// Reads the whole trace and writes it in the binary format of [`encode_samples`];
/// returns the sample count. The samples are held in memory (the count comes first):
/// meant for the short traces a QEMU image carries.
pub fn write_sample_bin<R: BufRead>(
    reader: &mut TraceReader<R>,
    mut out: impl Write,
) -> Result<u32> {
    let rate = reader.detect_sample_rate_hz()?.ok_or_else(|| {
        anyhow!(
            "{}: no sample rate (no `# {SAMPLE_RATE_KEY} = ...` line and fewer than two rows)",
            reader.name()
        )
    })?;
    let mut samples = Vec::new();
    while let Some(row) = reader.next_row()? {
        samples.push(row.to_sample());
    }
    let bytes = encode_samples(rate as f32, &samples)?;
    out.write_all(&bytes).context("writing the samples")?;
    out.flush().context("writing the samples")?;
    Ok(samples.len() as u32)
}
