//! Kistler DynoWare exports as trace rows, so that `replay` runs on real dynamometer data.
//!
//! # Design
//! A DynoWare text export is a header block (key-value lines such as
//! `Sampling rate [Hz]:,10000`; 19 lines in the exports we have, other versions differ),
//! the column line (`Time,Fx,Fy,Fz`, possibly with units, `Time [s]`, `Fx [N]`, and more
//! channels), an optional units line (`s,N,N,N`), then one line per sample. The column
//! line is the first whose first field is `Time...` and which names `Fx`; its delimiter
//! (tab, else `;`, else `,`) is the file's. With a tab or `;` delimiter a decimal comma is
//! read as a point (German-locale exports). Blank lines are skipped; any other line that
//! does not parse is an error naming the line.
//!
//! The dynamometer measures forces in its own axes. `--feed-axis` and `--normal-axis`
//! (`x`, `-x`, `y`, `-y`) say which signed dynamometer axis is the feed-frame `F_ax` and
//! `F_ay` of estimator-core's geometry (x along the feed, `F_ax > 0` resisting it). Note:
//! a dynamometer under the workpiece measures the force on the work, the opposite of the
//! force on the tool that the model describes, so the usual mapping negates both.
//!
//! There is no encoder channel: tooth-sync pulses are derived from the nominal spindle
//! speed, one per tooth period `T = 60 / (rpm N)` at `t = sync_phase + k T` in the file's
//! time base (the sample nearest each instant carries it). A real spindle is off its
//! nominal speed by a little, so the periods drift against the flutes slowly; over a few
//! seconds at 0.1 % that is a fraction of a tooth. The nominal feed goes into every row's
//! velocity (`[feed, 0]`: the feed frame is the axis frame here).
//!
//! The sample rate is the header's `Sampling rate`, else `1 / (t1 - t0)` from the first
//! two rows (read ahead); both present and disagreeing by more than 0.1 % is an error.

use anyhow::{anyhow, bail, Context, Result};
use std::collections::VecDeque;
use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::str::FromStr;

use crate::trace::{
    rate_from_times, FeedSignal, RowSource, SpindleSignal, TraceKind, TraceRow, Truth,
};

/// Header lines searched for the column line before giving up.
const MAX_HEADER_LINES: u64 = 200;

/// A signed dynamometer axis in the tool plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// `+Fx`.
    X,
    /// `-Fx`.
    NegX,
    /// `+Fy`.
    Y,
    /// `-Fy`.
    NegY,
}

impl Axis {
    /// The signed component of `(fx, fy)` along this axis.
    pub fn pick(self, fx: f32, fy: f32) -> f32 {
        match self {
            Axis::X => fx,
            Axis::NegX => -fx,
            Axis::Y => fy,
            Axis::NegY => -fy,
        }
    }

    fn is_x(self) -> bool {
        matches!(self, Axis::X | Axis::NegX)
    }
}

impl FromStr for Axis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" | "+x" => Ok(Axis::X),
            "-x" => Ok(Axis::NegX),
            "y" | "+y" => Ok(Axis::Y),
            "-y" => Ok(Axis::NegY),
            _ => Err(format!("`{s}` is not an axis (x, -x, y, -y)")),
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Axis::X => "x",
            Axis::NegX => "-x",
            Axis::Y => "y",
            Axis::NegY => "-y",
        })
    }
}

/// What the recording does not say: the cut's nominal speeds and the axis mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KistlerOptions {
    /// Nominal spindle speed [rpm].
    pub rpm: f64,
    /// Flutes of the cutter.
    pub flutes: u8,
    /// Nominal feed [mm/min].
    pub feed_mm_min: f64,
    /// Time of one tooth-sync pulse [s] (file time base); the others follow every tooth
    /// period.
    pub sync_phase_s: f64,
    /// Dynamometer axis that is the feed direction `F_ax`.
    pub feed_axis: Axis,
    /// Dynamometer axis that is the normal `F_ay`.
    pub normal_axis: Axis,
}

impl KistlerOptions {
    /// Checks the numbers and that the two axes differ.
    pub fn validate(&self) -> Result<()> {
        if !(self.rpm.is_finite() && self.rpm > 0.0) {
            bail!("spindle speed {} rpm: must be positive", self.rpm);
        }
        if self.flutes == 0 {
            bail!("flutes: must be at least 1");
        }
        if !(self.feed_mm_min.is_finite() && self.feed_mm_min > 0.0) {
            bail!("feed {} mm/min: must be positive", self.feed_mm_min);
        }
        if !self.sync_phase_s.is_finite() {
            bail!("sync phase {} s: not finite", self.sync_phase_s);
        }
        if self.feed_axis.is_x() == self.normal_axis.is_x() {
            bail!(
                "feed axis {} and normal axis {} are the same dynamometer axis",
                self.feed_axis,
                self.normal_axis
            );
        }
        Ok(())
    }

    /// Tooth period `60 / (rpm N)` [s].
    pub fn tooth_period_s(&self) -> f64 {
        60.0 / (self.rpm * self.flutes as f64)
    }

    /// Feed per tooth `feed / (N rpm)` [mm/tooth].
    pub fn tc_mm(&self) -> f64 {
        self.feed_mm_min / (self.flutes as f64 * self.rpm)
    }
}

/// One sample of the recording, in dynamometer axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Forces {
    /// Time [s], file time base.
    pub time_s: f64,
    /// `Fx` [N].
    pub fx_n: f32,
    /// `Fy` [N].
    pub fy_n: f32,
    /// `Fz` [N] (NaN if the file has no `Fz`).
    pub fz_n: f32,
}

/// Where the channels are.
#[derive(Clone, Copy, Debug)]
struct Columns {
    time: usize,
    fx: usize,
    fy: usize,
    fz: Option<usize>,
    /// Fields a data line needs at least.
    min_fields: usize,
}

/// Streaming reader of a DynoWare export, yielding raw force samples ([`Self::next_forces`])
/// or trace rows in the feed frame with derived sync pulses ([`Self::next_row`]).
pub struct KistlerReader<R: BufRead> {
    r: R,
    name: String,
    opts: KistlerOptions,
    header: Vec<(String, String)>,
    delimiter: char,
    decimal_comma: bool,
    cols: Columns,
    rate_hz: f64,
    line: u64,
    bytes: u64,
    buf: String,
    ahead: VecDeque<Forces>,
    /// Tooth index of the previous sample (sync derivation).
    prev_tooth: Option<i64>,
}

impl KistlerReader<BufReader<File>> {
    /// Opens a DynoWare export.
    pub fn open(path: &Path, opts: KistlerOptions) -> Result<KistlerReader<BufReader<File>>> {
        let name = path.display().to_string();
        let f = File::open(path).with_context(|| format!("cannot open {name}"))?;
        KistlerReader::new(BufReader::new(f), &name, opts)
    }
}

/// Channel name without units: `Fx [N]` -> `fx`, `Time[s]` -> `time`.
fn channel(name: &str) -> String {
    let base = name.split(['[', '(']).next().unwrap_or("");
    base.trim().trim_matches('"').trim().to_ascii_lowercase()
}

impl<R: BufRead> KistlerReader<R> {
    /// Reads the header block, the column line and the units line; determines the sample
    /// rate (reading up to two samples ahead if the header lacks it).
    pub fn new(r: R, name: &str, opts: KistlerOptions) -> Result<Self> {
        opts.validate().with_context(|| name.to_string())?;
        let mut rd = KistlerReader {
            r,
            name: name.to_string(),
            opts,
            header: Vec::new(),
            delimiter: ',',
            decimal_comma: false,
            cols: Columns {
                time: 0,
                fx: 0,
                fy: 0,
                fz: None,
                min_fields: 0,
            },
            rate_hz: 0.0,
            line: 0,
            bytes: 0,
            buf: String::new(),
            ahead: VecDeque::new(),
            prev_tooth: None,
        };
        let mut raw_header: Vec<(u64, String)> = Vec::new();
        loop {
            if !rd.read_line()? {
                bail!("{name}: no column line (`Time,Fx,Fy,Fz`) found; not a DynoWare export?");
            }
            if rd.line > MAX_HEADER_LINES {
                bail!(
                    "{name}: no column line (`Time,Fx,Fy,Fz`) in the first {MAX_HEADER_LINES} lines"
                );
            }
            let text = rd.buf.trim();
            if text.is_empty() {
                continue;
            }
            let delimiter = if text.contains('\t') {
                '\t'
            } else if text.contains(';') {
                ';'
            } else {
                ','
            };
            let fields: Vec<String> = text.split(delimiter).map(channel).collect();
            let is_columns = fields.first().is_some_and(|f| f.starts_with("time"))
                && fields.iter().any(|f| f == "fx");
            if !is_columns {
                raw_header.push((rd.line, text.to_string()));
                continue;
            }
            let find = |c: &str| fields.iter().position(|f| f == c);
            let missing: Vec<&str> = ["fx", "fy"]
                .into_iter()
                .filter(|c| find(c).is_none())
                .collect();
            if !missing.is_empty() {
                bail!(
                    "{name} line {}: missing channel{} {} (columns: {text})",
                    rd.line,
                    if missing.len() > 1 { "s" } else { "" },
                    missing.join(", ")
                );
            }
            let (fx, fy, fz) = (find("fx").unwrap_or(0), find("fy").unwrap_or(0), find("fz"));
            rd.cols = Columns {
                time: 0,
                fx,
                fy,
                fz,
                min_fields: 1 + fx.max(fy).max(fz.unwrap_or(0)),
            };
            rd.delimiter = delimiter;
            rd.decimal_comma = delimiter != ',';
            break;
        }
        // Header lines are `key: value` (the delimiter may follow the colon).
        let mut header_rate = None;
        for (line, text) in raw_header {
            let (key, value) = match text.split_once(':') {
                Some((k, v)) => (k, v),
                None => text.split_once(rd.delimiter).unwrap_or((text.as_str(), "")),
            };
            let value = value
                .trim_start_matches([',', ';', '\t', ' '])
                .trim_end_matches([',', ';', '\t', ' ']);
            let key = key.trim().to_string();
            if key.to_ascii_lowercase().starts_with("sampling rate") {
                let rate = rd
                    .number(value)
                    .filter(|r| r.is_finite() && *r > 0.0)
                    .ok_or_else(|| {
                        anyhow!(
                            "{name} line {line}: sampling rate `{value}` is not a positive number"
                        )
                    })?;
                header_rate = Some(rate);
            }
            rd.header.push((key, value.to_string()));
        }
        // Units line: the first non-blank line after the columns, if its time is not a number.
        let mut units_checked = false;
        while rd.ahead.len() < 2 {
            match rd.read_forces(!units_checked)? {
                Some(f) => rd.ahead.push_back(f),
                None => break,
            }
            units_checked = true;
        }
        let from_times = match (rd.ahead.front(), rd.ahead.get(1)) {
            (Some(a), Some(b)) => rate_from_times(a.time_s, b.time_s),
            _ => None,
        };
        rd.rate_hz = match (header_rate, from_times) {
            (Some(h), Some(t)) if (h - t).abs() > 1e-3 * h => bail!(
                "{name}: the header's sampling rate ({h} Hz) disagrees with the time stamps ({t} Hz)"
            ),
            (Some(h), _) => h,
            (None, Some(t)) => t,
            (None, None) => bail!(
                "{name}: no sampling rate in the header and fewer than two samples to tell it"
            ),
        };
        Ok(rd)
    }

    /// A number in the file's locale.
    fn number(&self, text: &str) -> Option<f64> {
        let t = text.trim();
        if self.decimal_comma && t.contains(',') {
            t.replace(',', ".").parse().ok()
        } else {
            t.parse().ok()
        }
    }

    fn read_line(&mut self) -> Result<bool> {
        self.buf.clear();
        let n = self
            .r
            .read_line(&mut self.buf)
            .with_context(|| format!("{}: cannot read after line {}", self.name, self.line))?;
        if n == 0 {
            return Ok(false);
        }
        self.line += 1;
        self.bytes += n as u64;
        Ok(true)
    }

    /// The next sample line; `may_be_units`: the first line after the columns, skipped if
    /// its time field is not a number.
    fn read_forces(&mut self, mut may_be_units: bool) -> Result<Option<Forces>> {
        loop {
            if !self.read_line()? {
                return Ok(None);
            }
            let text = self.buf.trim();
            if text.is_empty() {
                continue;
            }
            let fields: Vec<&str> = text.split(self.delimiter).collect();
            let c = self.cols;
            let time = fields.get(c.time).and_then(|t| self.number(t));
            if time.is_none() && may_be_units {
                may_be_units = false;
                continue;
            }
            if fields.len() < c.min_fields {
                bail!(
                    "{} line {}: {} fields, the force channels need {}",
                    self.name,
                    self.line,
                    fields.len(),
                    c.min_fields
                );
            }
            let get = |i: usize, col: &str| -> Result<f64> {
                let raw = fields.get(i).copied().unwrap_or("").trim();
                if raw.is_empty() {
                    bail!(
                        "{} line {}, column {col}: empty value",
                        self.name,
                        self.line
                    );
                }
                self.number(raw).ok_or_else(|| {
                    anyhow!(
                        "{} line {}, column {col}: `{raw}` is not a number",
                        self.name,
                        self.line
                    )
                })
            };
            let time_s = get(c.time, "Time")?;
            let fx_n = get(c.fx, "Fx")? as f32;
            let fy_n = get(c.fy, "Fy")? as f32;
            let fz_n = match c.fz {
                Some(i) => get(i, "Fz")? as f32,
                None => f32::NAN,
            };
            return Ok(Some(Forces {
                time_s,
                fx_n,
                fy_n,
                fz_n,
            }));
        }
    }

    /// The header block as `(key, value)` pairs, in order (`Sampling rate [Hz]`, `10000`).
    pub fn header(&self) -> &[(String, String)] {
        &self.header
    }

    /// Sample rate [Hz] (header, or time stamps).
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// The options the rows are built with.
    pub fn options(&self) -> &KistlerOptions {
        &self.opts
    }

    /// The next sample in dynamometer axes.
    pub fn next_forces(&mut self) -> Result<Option<Forces>> {
        if let Some(f) = self.ahead.pop_front() {
            return Ok(Some(f));
        }
        self.read_forces(false)
    }

    /// Whether the sample at `time_s` carries a tooth pulse: the tooth index
    /// `floor((t - phase) / T + h)` (`h` half a sample in periods) changed since the
    /// previous sample. The first sample counts against a virtual one a sample earlier.
    fn pulse(&mut self, time_s: f64) -> bool {
        let period = self.opts.tooth_period_s();
        let x = (time_s - self.opts.sync_phase_s) / period;
        let h = 0.5 / (self.rate_hz * period);
        let k = (x + h).floor() as i64;
        let prev = self.prev_tooth.unwrap_or_else(|| (x - h).floor() as i64);
        self.prev_tooth = Some(k);
        k != prev
    }

    /// The next sample as a trace row: feed-frame forces, nominal feed velocity, a derived
    /// sync pulse, spindle 0, no truth.
    pub fn next_row(&mut self) -> Result<Option<TraceRow>> {
        let Some(f) = self.next_forces()? else {
            return Ok(None);
        };
        let o = self.opts;
        Ok(Some(TraceRow {
            time_s: f.time_s,
            sync: self.pulse(f.time_s),
            feed: [
                o.feed_axis.pick(f.fx_n, f.fy_n),
                o.normal_axis.pick(f.fx_n, f.fy_n),
            ],
            feed_velocity_mm_min: [o.feed_mm_min as f32, 0.0],
            spindle: 0.0,
            truth: Truth::default(),
        }))
    }
}

impl<R: BufRead> RowSource for KistlerReader<R> {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> TraceKind {
        TraceKind {
            feed: FeedSignal::Force,
            two_axis: true,
            has_velocity: true,
            spindle: SpindleSignal::None,
            has_truth: false,
        }
    }
    fn sample_rate_hz(&self) -> Option<f64> {
        Some(self.rate_hz)
    }
    fn detect_sample_rate_hz(&mut self) -> Result<Option<f64>> {
        Ok(Some(self.rate_hz))
    }
    fn next_row(&mut self) -> Result<Option<TraceRow>> {
        KistlerReader::next_row(self)
    }
    fn bytes_read(&self) -> u64 {
        self.bytes
    }
}
