//! The per-tooth records CSV that `replay` writes: one row per [`ToothRecord`], the
//! Monitor's whole output, plus the ground truth where the trace has it. Format:
//! docs/formats.md ("Per-tooth records CSV").
//!
//! Numbers are written in Rust's shortest round-trip form, so [`RecordReader`] gets the
//! same bits back (tests, tools that post-process a replay). `end_sample` is not a column:
//! `time_s` is the time stamp of the trace row at `end_sample` (the period's last sample),
//! which keeps the trace's own time base (a recording that starts at 2 s).

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::{Method, Status, ToothRecord};
use std::io::{Read, Write};

use crate::trace::Truth;

/// Columns of every records file, in order.
pub const COLUMNS: [&str; 20] = [
    "time_s",
    "tooth",
    "samples",
    "rpm",
    "tc_mm",
    "fx_n",
    "f2_n",
    "fx_filt_n",
    "f2_filt_n",
    "tc_filt_mm",
    "rr",
    "ra",
    "dr_mm",
    "da_mm",
    "dr_sigma_mm",
    "da_sigma_mm",
    "status",
    "method",
    "handover_z",
    "handover_n",
];

/// Columns appended when the trace has ground truth: the truth at the record's end sample.
pub const TRUTH_COLUMNS: [&str; 3] = ["true_dr_mm", "true_da_mm", "true_tc_mm"];

/// [`Method`] from its [`Method::name`].
pub fn parse_method(s: &str) -> Option<Method> {
    [
        Method::None,
        Method::Polynomial,
        Method::Table3,
        Method::Inversion,
    ]
    .into_iter()
    .find(|m| m.name() == s.trim())
}

/// One row of a records file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordRow {
    /// End time of the period [s] (trace time base).
    pub time_s: f64,
    /// The record; `end_sample` is 0 (not stored).
    pub record: ToothRecord,
    /// `dr_mm`, `da_mm`, `tc_mm` of the truth (others NaN) when the file has them.
    pub truth: Option<Truth>,
}

/// Streaming writer of the records CSV.
pub struct RecordWriter<W: Write> {
    w: csv::Writer<W>,
    with_truth: bool,
    rows: u64,
}

impl<W: Write> RecordWriter<W> {
    /// Writes the header; `with_truth` adds [`TRUTH_COLUMNS`].
    pub fn new(w: W, with_truth: bool) -> Result<Self> {
        let mut w = csv::Writer::from_writer(w);
        let mut header: Vec<&str> = COLUMNS.to_vec();
        if with_truth {
            header.extend(TRUTH_COLUMNS);
        }
        w.write_record(&header)
            .context("writing the records header")?;
        Ok(RecordWriter {
            w,
            with_truth,
            rows: 0,
        })
    }

    /// Writes one record ending at `time_s`; `truth` is used iff the file has truth columns.
    pub fn write(&mut self, time_s: f64, r: &ToothRecord, truth: &Truth) -> Result<()> {
        let mut f: Vec<String> = vec![
            time_s.to_string(),
            r.tooth.to_string(),
            r.samples.to_string(),
            r.rpm.to_string(),
            r.tc_mm.to_string(),
            r.fx_n.to_string(),
            r.f2_n.to_string(),
            r.fx_filt_n.to_string(),
            r.f2_filt_n.to_string(),
            r.tc_filt_mm.to_string(),
            r.rr.to_string(),
            r.ra.to_string(),
            r.dr_mm.to_string(),
            r.da_mm.to_string(),
            r.dr_sigma_mm.to_string(),
            r.da_sigma_mm.to_string(),
            r.status.to_string(),
            r.method.name().to_string(),
            r.handover_z.to_string(),
            r.handover_n.to_string(),
        ];
        if self.with_truth {
            f.extend([
                truth.dr_mm.to_string(),
                truth.da_mm.to_string(),
                truth.tc_mm.to_string(),
            ]);
        }
        self.rows += 1;
        self.w.write_record(&f).context("writing the records")
    }

    /// Records written.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Flushes and hands back the writer.
    pub fn finish(self) -> Result<W> {
        self.w
            .into_inner()
            .map_err(|e| anyhow!("writing the records: {}", e.error()))
    }
}

/// Streaming reader of the records CSV (for tests and post-processing).
pub struct RecordReader<R: Read> {
    rd: csv::Reader<R>,
    name: String,
    /// Index of each of [`COLUMNS`] then [`TRUTH_COLUMNS`] in the file.
    at: [usize; 20],
    truth_at: Option<[usize; 3]>,
    fields: usize,
    rec: csv::StringRecord,
}

impl<R: Read> RecordReader<R> {
    /// Reads the header; every column of [`COLUMNS`] is required, the truth columns all or
    /// none. `name` names the input in messages.
    pub fn new(r: R, name: &str) -> Result<Self> {
        let mut rd = csv::ReaderBuilder::new().flexible(true).from_reader(r);
        let header = rd
            .headers()
            .with_context(|| format!("{name}: cannot read the header"))?
            .clone();
        let find = |c: &str| header.iter().position(|h| h.trim() == c);
        let missing: Vec<&str> = COLUMNS
            .iter()
            .copied()
            .filter(|c| find(c).is_none())
            .collect();
        if !missing.is_empty() {
            bail!("{name} line 1: missing columns `{}`", missing.join("`, `"));
        }
        let at = COLUMNS.map(|c| find(c).unwrap_or(0));
        let truth = TRUTH_COLUMNS.map(find);
        let truth_at = match truth {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            [None, None, None] => None,
            _ => bail!(
                "{name} line 1: give all of `{}` or none",
                TRUTH_COLUMNS.join("`, `")
            ),
        };
        Ok(RecordReader {
            rd,
            name: name.to_string(),
            at,
            truth_at,
            fields: header.len(),
            rec: csv::StringRecord::new(),
        })
    }

    /// Whether the file has the truth columns.
    pub fn has_truth(&self) -> bool {
        self.truth_at.is_some()
    }

    fn text(&self, col: usize) -> &str {
        self.rec.get(col).unwrap_or("").trim()
    }

    fn err(&self, col: &str, what: &str, text: &str) -> anyhow::Error {
        let line = self.rec.position().map_or(0, |p| p.line());
        anyhow!(
            "{} line {line}, column `{col}`: `{text}` is not {what}",
            self.name
        )
    }

    fn num<T: std::str::FromStr>(&self, k: usize) -> Result<T> {
        let t = self.text(self.at[k]);
        t.parse::<T>()
            .map_err(|_| self.err(COLUMNS[k], "a number", t))
    }

    /// The next row, `None` at the end.
    pub fn next_row(&mut self) -> Result<Option<RecordRow>> {
        if !self
            .rd
            .read_record(&mut self.rec)
            .with_context(|| format!("{}: cannot read", self.name))?
        {
            return Ok(None);
        }
        if self.rec.len() != self.fields {
            let line = self.rec.position().map_or(0, |p| p.line());
            bail!(
                "{} line {line}: {} fields, the header has {}",
                self.name,
                self.rec.len(),
                self.fields
            );
        }
        let status_text = self.text(self.at[16]);
        let status = Status::parse(status_text)
            .ok_or_else(|| self.err("status", "a status", status_text))?;
        let method_text = self.text(self.at[17]);
        let method = parse_method(method_text)
            .ok_or_else(|| self.err("method", "a method name", method_text))?;
        let record = ToothRecord {
            end_sample: 0,
            tooth: self.num(1)?,
            samples: self.num(2)?,
            rpm: self.num(3)?,
            tc_mm: self.num(4)?,
            fx_n: self.num(5)?,
            f2_n: self.num(6)?,
            fx_filt_n: self.num(7)?,
            f2_filt_n: self.num(8)?,
            tc_filt_mm: self.num(9)?,
            rr: self.num(10)?,
            ra: self.num(11)?,
            dr_mm: self.num(12)?,
            da_mm: self.num(13)?,
            dr_sigma_mm: self.num(14)?,
            da_sigma_mm: self.num(15)?,
            status,
            method,
            handover_z: self.num(18)?,
            handover_n: self.num(19)?,
        };
        let truth = match self.truth_at {
            None => None,
            Some(at) => {
                let v = |k: usize| -> Result<f32> {
                    let t = self.text(at[k]);
                    t.parse::<f32>()
                        .map_err(|_| self.err(TRUTH_COLUMNS[k], "a number", t))
                };
                Some(Truth {
                    dr_mm: v(0)?,
                    da_mm: v(1)?,
                    tc_mm: v(2)?,
                    ..Truth::default()
                })
            }
        };
        Ok(Some(RecordRow {
            time_s: self.num(0)?,
            record,
            truth,
        }))
    }
}
