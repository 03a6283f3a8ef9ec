//! `replay`: a raw trace (or a dynamometer recording) through the streaming Monitor, one
//! [`ToothRecord`] per tooth period out, exactly as the firmware runs it.
//!
//! # Design
//! `rows -> Sample -> Pipeline::process (Monitor, then Alarms) -> record + alarm output ->
//! per-record stage -> output`. The pipeline is `estimator_core::MachineConfig::build`: the
//! firmware's code path, on the host. Everything that happens once per record after it
//! lives in [`PerRecord::record`]: counting, error statistics against the truth, alarm
//! events and their latency against the truth's flute damage. Outputs (records CSV,
//! `--bits` lines, alarm events, plot data) hang off the callback, so the library API
//! ([`replay`]) and the command share one loop.
//!
//! A record's time and truth are those of the trace row at its `end_sample`, the period's
//! last sample: the row before the pulse that closed it (or, for a `no_sync` timeout, the
//! row that timed it out). The error statistics compare a valid estimate with the truth
//! averaged over the teeth its filter window holds (`filter_revs x flutes`): that is what
//! a filtered estimate measures (the last tooth's truth would charge the filter's lag
//! during a ramp as an error of the estimator).
//!
//! Before the first sample, replay refuses what cannot work: a trace sampled at another
//! rate than the config's (relative difference above [`RATE_TOL`]), a force trace with a
//! motor config or the reverse, a spindle signal the spindle model does not read, a
//! one-axis trace for a two-axis drive, and a trace without velocity columns for a config
//! that measures the feed velocity (it needs `feed_velocity = { nominal = [vx, vy] }`).
//!
//! The machine file (`--config`) is a TOML [`MonitorConfig`] plus an optional `[alarms]`
//! table ([`AlarmConfig`]) and an optional `[front_end]` table ([`FrontEnd`]: the board's
//! input scaling, checked but not used by replay, whose trace is already in signal units),
//! each laid over its defaults by [`crate::config::override_from`]
//! (unknown keys are errors naming the key). Enum variants
//! with fields are the one thing an overlay cannot merge into a different default: a
//! `[input.motor.spindle.load]` table therefore starts from paper 003's FANUC model
//! ([`SpindleModel::paper003`]) rather than from the default current model.

use anyhow::{anyhow, bail, Result};
use estimator_core::alarm::{AlarmConfig, AlarmEvent, AlarmOutput, Cause};
use estimator_core::drive::SpindleModel;
use estimator_core::frontend::FrontEnd;
use estimator_core::monitor::{FeedVelocity, Input};
use estimator_core::{MachineConfig, MonitorConfig, PipelineState, Status, ToothRecord};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::config;
use crate::kistler::{Axis, KistlerOptions, KistlerReader};
use crate::plot::{PlotData, PlotPoint};
use crate::records::RecordWriter;
use crate::trace::{
    FeedSignal, RowSource, SpindleSignal, TraceKind, TraceReader, TraceRow, TraceWriter, Truth,
};

/// Largest relative difference between the config's sample rate and the trace's.
pub const RATE_TOL: f64 = 1e-4;

/// Samples between progress-bar updates.
const PROGRESS_EVERY: u64 = 1 << 16;

/// Number of status flags ([`Status::NAMES`]).
pub const FLAGS: usize = Status::NAMES.len();

/// One record as the per-record stage hands it on.
#[derive(Clone, Copy, Debug)]
pub struct ReplayEvent<'a> {
    /// Record index, from 0.
    pub index: u64,
    /// Time stamp of the trace row at `record.end_sample`, the period's last sample [s].
    pub time_s: f64,
    /// The Monitor's record.
    pub record: &'a ToothRecord,
    /// Truth of that row (NaN where the trace has none).
    pub truth: &'a Truth,
    /// What the alarms said after this record (`event` is set on the record that raised
    /// one).
    pub alarm: &'a AlarmOutput,
}

/// An alarm as replay reports it: the event, when, and how long after the truth's first
/// flute damage (or tool loss) it came.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReplayAlarm {
    /// Index of the record that raised it (or named a drop trip's cause).
    pub index: u64,
    /// Its time [s].
    pub time_s: f64,
    /// When the output latched [s]: the record's time, or earlier for a drop trip inside
    /// a period (see [`latched_time_s`]).
    pub latched_s: f64,
    /// The event.
    pub event: AlarmEvent,
    /// Time since the truth first showed a damaged flute [s], if it did by then.
    pub latency_s: Option<f64>,
    /// Teeth since then (tooth periods at the alarm's speed).
    pub latency_teeth: Option<f64>,
}

/// Distribution of the relative error of one estimate against the truth.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// Valid records with a finite, positive truth.
    pub count: u64,
    /// Median of `|est - true| / true`.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Largest.
    pub max: f64,
    /// Records whose truth lies within the estimate's ±2 sigma band.
    pub within_2_sigma: u64,
}

impl ErrorStats {
    /// Fraction of `count` within ±2 sigma (NaN for no records).
    pub fn coverage(&self) -> f64 {
        self.within_2_sigma as f64 / self.count as f64
    }
}

/// Errors of the valid records against the trace's truth.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TruthErrors {
    /// Radial depth.
    pub dr: ErrorStats,
    /// Axial depth.
    pub da: ErrorStats,
}

/// What a replay did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReplaySummary {
    /// Sample rate the Monitor ran at [Hz].
    pub sample_rate_hz: f64,
    /// Samples read.
    pub samples: u64,
    /// Tooth records produced.
    pub records: u64,
    /// Records whose status is valid.
    pub valid: u64,
    /// Records carrying each flag, in [`Status::NAMES`] order.
    pub flags: [u64; FLAGS],
    /// Errors against the truth, when the trace has truth columns.
    pub errors: Option<TruthErrors>,
    /// Alarm events raised (the wear warning included).
    pub alarm_events: u64,
    /// The first alarm that latched the output, if any.
    pub first_alarm: Option<ReplayAlarm>,
    /// When the truth first showed a damaged flute [s].
    pub damage_s: Option<f64>,
}

impl ReplaySummary {
    /// Trace length [s].
    pub fn duration_s(&self) -> f64 {
        self.samples as f64 / self.sample_rate_hz
    }

    /// A few lines for stderr: counts, flags, errors against the truth.
    pub fn report(&self, name: &str) -> String {
        let mut s = format!(
            "{name}: {} samples ({:.3} s at {} Hz), {} tooth records, {} valid, {} flagged\n",
            self.samples,
            self.duration_s(),
            self.sample_rate_hz,
            self.records,
            self.valid,
            self.records - self.valid
        );
        let flags: Vec<String> = Status::NAMES
            .iter()
            .zip(self.flags)
            .filter(|(_, n)| *n > 0)
            .map(|((_, name), n)| format!("{name} {n}"))
            .collect();
        if !flags.is_empty() {
            s += &format!("  records by flag: {}\n", flags.join(", "));
        }
        if let Some(e) = &self.errors {
            for (what, st) in [("d_r", &e.dr), ("d_a", &e.da)] {
                if st.count == 0 {
                    s += &format!("  {what} vs truth: no valid record with a known truth\n");
                } else {
                    s += &format!(
                        "  {what} vs the window-mean truth over {} valid records: relative error p50 {:.2} %, \
                         p95 {:.2} %, max {:.2} %; truth within ±2 sigma in {:.1} %\n",
                        st.count,
                        st.p50 * 100.0,
                        st.p95 * 100.0,
                        st.max * 100.0,
                        st.coverage() * 100.0
                    );
                }
            }
        }
        match (&self.first_alarm, self.damage_s) {
            (Some(a), _) => {
                s.push_str(&format!(
                    "alarm: {} at {:.4} s (record {}, tooth {}",
                    a.event.cause.name(),
                    a.latched_s,
                    a.index,
                    a.event.record.tooth
                ));
                if a.latched_s < a.time_s {
                    s.push_str(&format!(
                        "; a drop trip inside a period, named at {:.4} s",
                        a.time_s
                    ));
                }
                s.push(')');
                if let (Some(l), Some(t)) = (a.latency_s, a.latency_teeth) {
                    s.push_str(&format!(
                        ", {:.1} ms = {:.1} teeth after the first flute damage",
                        1e3 * l,
                        t
                    ));
                }
                s.push('\n');
            }
            (None, Some(d)) => {
                s.push_str(&format!("no alarm, but a flute was damaged at {d:.4} s\n"))
            }
            (None, None) => s.push_str("no alarm\n"),
        }
        s
    }
}

/// Collects relative errors and band coverage.
#[derive(Default)]
struct ErrorAcc {
    rel: Vec<f64>,
    within: u64,
}

impl ErrorAcc {
    fn push(&mut self, est: f32, sigma: f32, truth: f32) {
        if !(truth.is_finite() && truth > 0.0) {
            return;
        }
        let err = f64::from(est) - f64::from(truth);
        self.rel.push(err.abs() / f64::from(truth));
        self.within += u64::from(err.abs() <= 2.0 * f64::from(sigma));
    }

    fn stats(mut self) -> ErrorStats {
        let n = self.rel.len();
        if n == 0 {
            return ErrorStats::default();
        }
        self.rel.sort_by(f64::total_cmp);
        // Nearest rank.
        let pct = |p: f64| self.rel[((p * n as f64).ceil() as usize).clamp(1, n) - 1];
        ErrorStats {
            count: n as u64,
            p50: pct(0.5),
            p95: pct(0.95),
            max: self.rel[n - 1],
            within_2_sigma: self.within,
        }
    }
}

/// Everything that happens once per record after the Monitor.
struct PerRecord {
    summary: ReplaySummary,
    truth: Option<(ErrorAcc, ErrorAcc)>,
    /// Truth `(d_r, d_a)` of the last `window` records: a filtered estimate is compared
    /// with the mean engagement over the teeth it averaged, not with the last tooth's.
    recent: std::collections::VecDeque<(f32, f32)>,
    window: usize,
    /// The truth's flute mask at the start (damage is a change from it).
    intact_at_start: Option<u32>,
}

impl PerRecord {
    fn new(sample_rate_hz: f64, has_truth: bool, window: usize) -> Self {
        PerRecord {
            summary: ReplaySummary {
                sample_rate_hz,
                ..ReplaySummary::default()
            },
            truth: has_truth.then(|| (ErrorAcc::default(), ErrorAcc::default())),
            intact_at_start: None,
            recent: std::collections::VecDeque::with_capacity(window),
            window: window.max(1),
        }
    }

    fn record(
        &mut self,
        rec: &ToothRecord,
        alarm: &AlarmOutput,
        time_s: f64,
        truth: &Truth,
        on_record: &mut impl FnMut(&ReplayEvent<'_>) -> Result<()>,
    ) -> Result<()> {
        let s = &mut self.summary;
        let index = s.records;
        s.records += 1;
        s.valid += u64::from(rec.status.is_valid());
        for (n, (flag, _)) in s.flags.iter_mut().zip(Status::NAMES) {
            *n += u64::from(rec.status.contains(flag));
        }
        // Only teeth the Monitor puts in its window count (cutting, valid periods); an
        // air cut empties it, as it empties the Monitor's.
        if rec.status.contains(Status::NOT_CUTTING) {
            self.recent.clear();
        } else if !rec
            .status
            .intersects(Status::PERIOD_INVALID | Status::INPUT_FAULT | Status::NON_FINITE)
        {
            if self.recent.len() == self.window {
                self.recent.pop_front();
            }
            self.recent.push_back((truth.dr_mm, truth.da_mm));
        }
        if let (Some((dr, da)), true) = (&mut self.truth, rec.status.is_valid()) {
            let n = self.recent.len().max(1) as f32;
            let (t_dr, t_da) = self
                .recent
                .iter()
                .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
            dr.push(rec.dr_mm, rec.dr_sigma_mm, t_dr / n);
            da.push(rec.da_mm, rec.da_sigma_mm, t_da / n);
        }
        // Flute damage in the truth: the first change of the intact mask.
        let start = *self.intact_at_start.get_or_insert(truth.flutes_intact);
        if s.damage_s.is_none() && truth.flutes_intact != start {
            s.damage_s = Some(time_s);
        }
        if let Some(event) = alarm.event {
            s.alarm_events += 1;
            if s.first_alarm.is_none() && event.cause != Cause::Wear {
                let latched_s = latched_time_s(time_s, &event, s.sample_rate_hz);
                let latency_s = s.damage_s.map(|d| latched_s - d);
                let tooth_s = f64::from(rec.samples) / s.sample_rate_hz;
                s.first_alarm = Some(ReplayAlarm {
                    index,
                    time_s,
                    latched_s,
                    event,
                    latency_s,
                    latency_teeth: latency_s.map(|l| l / tooth_s),
                });
            }
        }
        on_record(&ReplayEvent {
            index,
            time_s,
            record: rec,
            truth,
            alarm,
        })
    }

    fn finish(self, samples: u64) -> ReplaySummary {
        let mut s = self.summary;
        s.samples = samples;
        s.errors = self.truth.map(|(dr, da)| TruthErrors {
            dr: dr.stats(),
            da: da.stats(),
        });
        s
    }
}

/// Refuses configurations that cannot read this trace (see the module docs).
pub fn check_compatible(kind: &TraceKind, cfg: &MonitorConfig, name: &str) -> Result<()> {
    match (&cfg.input, kind.feed) {
        (Input::Dynamometer, FeedSignal::Current) => bail!(
            "{name} carries motor currents (`feed_x_a`) but the config's input is a dynamometer"
        ),
        (Input::Motor { .. }, FeedSignal::Force) => bail!(
            "{name} carries dynamometer forces (`fx_n`, `fy_n`) but the config's input is a \
             motor; set `input = \"dynamometer\"`"
        ),
        (Input::Motor { feed, spindle }, FeedSignal::Current) => {
            match (spindle, kind.spindle) {
                (SpindleModel::Current { .. }, SpindleSignal::Current)
                | (SpindleModel::Load { .. }, SpindleSignal::Load) => {}
                (SpindleModel::Current { .. }, _) => bail!(
                    "{name} has no `spindle_a` column, which the config's current spindle model reads"
                ),
                (SpindleModel::Load { .. }, _) => bail!(
                    "{name} has no `spindle_load_pct` column, which the config's load spindle model reads"
                ),
            }
            if feed.two_axis && !kind.two_axis {
                bail!("{name} has one feed axis (no `feed_y_a`) but the config's drive has two");
            }
        }
        (Input::Dynamometer, FeedSignal::Force) => {}
    }
    if !kind.has_velocity && cfg.feed_velocity == FeedVelocity::Measured {
        bail!(
            "{name} has no feed velocity columns (`feed_vx_mm_min`): give the programmed feed \
             in the config, `feed_velocity = {{ nominal = [vx, vy] }}` (mm/min)"
        );
    }
    Ok(())
}

/// Replays a raw trace: every tooth record and the truth at its end sample go to
/// `on_record`. The Monitor is `cfg.clone().build()`; its configuration errors come back
/// with the core's message. Checks the trace against `cfg` first (see the module docs).
pub fn replay<R: BufRead>(
    reader: &mut TraceReader<R>,
    cfg: &MonitorConfig,
    mut on_record: impl FnMut(&ToothRecord, &Truth),
) -> Result<ReplaySummary> {
    replay_source(reader, cfg, &AlarmConfig::default(), None, |e| {
        on_record(e.record, e.truth);
        Ok(())
    })
}

/// [`replay`] for any [`RowSource`], with the full event (index, time) and a progress bar
/// advanced by bytes read. An error from `on_record` stops the replay.
pub fn replay_source<S: RowSource + ?Sized>(
    src: &mut S,
    cfg: &MonitorConfig,
    alarms: &AlarmConfig,
    progress: Option<&ProgressBar>,
    mut on_record: impl FnMut(&ReplayEvent<'_>) -> Result<()>,
) -> Result<ReplaySummary> {
    let kind = src.kind();
    let name = src.name().to_string();
    check_compatible(&kind, cfg, &name)?;
    let cfg_rate = f64::from(cfg.sample_rate_hz);
    if let Some(rate) = src.detect_sample_rate_hz()? {
        if (cfg_rate - rate).abs() > RATE_TOL * rate {
            bail!("{name} is sampled at {rate} Hz but the config says sample_rate_hz = {cfg_rate}");
        }
    }
    let pipeline = MachineConfig {
        monitor: cfg.clone(),
        alarms: *alarms,
        front_end: FrontEnd::default(),
    }
    .build()
    .map_err(|e| anyhow!("machine configuration: {e}"))?;
    let mut st = PipelineState::default();
    let window = usize::from(cfg.filter_revs) * usize::from(cfg.estimator.tool.flutes);
    let mut stage = PerRecord::new(cfg_rate, kind.has_truth, window);
    let mut n: u64 = 0;
    let mut prev = TraceRow::default();
    while let Some(row) = src.next_row()? {
        if let Some((rec, alarm)) = pipeline.process(&mut st, &row.to_sample()) {
            // A pulse closes the period at the sample before it; a timeout at this one.
            let end = if rec.end_sample == n { &row } else { &prev };
            debug_assert!(rec.end_sample == n || rec.end_sample + 1 == n);
            stage.record(&rec, &alarm, end.time_s, &end.truth, &mut on_record)?;
        }
        prev = row;
        n += 1;
        if n % PROGRESS_EVERY == 0 {
            if let Some(pb) = progress {
                pb.set_position(src.bytes_read());
            }
        }
    }
    if let Some(pb) = progress {
        pb.finish_and_clear();
    }
    Ok(stage.finish(n))
}

/// How `replay` writes its records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordFormat {
    /// The per-tooth records CSV ([`crate::records`]).
    Csv,
    /// One line per record: `"{idx} {w0:08x} {w1:08x} ..."` of [`ToothRecord::to_words`].
    Bits,
}

/// One `--bits` line: the record index, then each word as 8 hex digits, then `\n`.
///
/// Note: the same text as tests/target-check's `write_case`, replicated rather than
/// depended on, so that host-sim builds whatever state the QEMU crate is in (and that crate
/// may itself depend on host-sim). A test pins the format.
pub fn bits_line(idx: u64, words: &[u32]) -> String {
    use std::fmt::Write as _;
    let mut s = idx.to_string();
    for w in words {
        let _ = write!(s, " {w:08x}");
    }
    s.push('\n');
    s
}

/// What [`replay_to`] runs and writes besides the records.
#[derive(Clone, Debug, Default)]
pub struct ReplayOutputs {
    /// Collect the records for a plot.
    pub plot: bool,
    /// The alarm detectors (the machine file's `[alarms]`).
    pub alarms: AlarmConfig,
    /// Collect the alarm events (for `--alarms FILE`).
    pub events: bool,
}

/// The alarm-events CSV (`--alarms`): one row per event, at the record that raised it
/// (`time_s`: its time). A drop trip inside a period (`estimator_core::handover`) latches
/// the output before its record (`latched_s`: when the output latched; the record's time
/// otherwise); its event comes with the record that names its cause, up to three records
/// later (`value`: the force lost, `threshold`: the trip's limit).
pub const ALARM_COLUMNS: &str = "time_s,latched_s,record,tooth,cause,value,threshold,latched";

/// When an event's output latched on the trace's time line: the time of the record it
/// came with, less the samples from the latch to that record's last sample.
pub fn latched_time_s(record_time_s: f64, ev: &AlarmEvent, sample_rate_hz: f64) -> f64 {
    record_time_s - ev.record.end_sample.saturating_sub(ev.latched_sample) as f64 / sample_rate_hz
}

/// One row of the alarm-events CSV.
pub fn alarm_row(e: &ReplayEvent<'_>, ev: &AlarmEvent, sample_rate_hz: f64) -> String {
    format!(
        "{},{},{},{},{},{},{},{}\n",
        e.time_s,
        latched_time_s(e.time_s, ev, sample_rate_hz),
        e.index,
        e.record.tooth,
        ev.cause.name(),
        ev.value,
        ev.threshold,
        u8::from(e.alarm.latched)
    )
}

/// The `replay` command's loop: records to `out` in `format`, plot data if asked for.
pub fn replay_to<S: RowSource + ?Sized, W: Write>(
    src: &mut S,
    cfg: &MonitorConfig,
    out: W,
    format: RecordFormat,
    outputs: &ReplayOutputs,
    progress: Option<&ProgressBar>,
) -> Result<(ReplaySummary, Option<PlotData>, String)> {
    let mut events = String::new();
    if outputs.events {
        events.push_str(ALARM_COLUMNS);
        events.push('\n');
    }
    let rate = f64::from(cfg.sample_rate_hz);
    let has_truth = src.kind().has_truth;
    let mut plot = outputs.plot.then(|| PlotData {
        title: src.name().to_string(),
        dynamometer: cfg.input == Input::Dynamometer,
        points: Vec::new(),
        alarms: Vec::new(),
    });
    let summary = match format {
        RecordFormat::Csv => {
            let mut wr = RecordWriter::new(out, has_truth)?;
            let s = replay_source(src, cfg, &outputs.alarms, progress, |e| {
                collect(&mut plot, &mut events, outputs.events, rate, e);
                wr.write(e.time_s, e.record, e.truth)
            })?;
            wr.finish()?;
            s
        }
        RecordFormat::Bits => {
            let mut out = out;
            let s = replay_source(src, cfg, &outputs.alarms, progress, |e| {
                collect(&mut plot, &mut events, outputs.events, rate, e);
                out.write_all(bits_line(e.index, &e.record.to_words()).as_bytes())
                    .map_err(|err| anyhow!("writing the records: {err}"))
            })?;
            out.flush()
                .map_err(|err| anyhow!("writing the records: {err}"))?;
            s
        }
    };
    Ok((summary, plot, events))
}

/// Plot points, alarm lines (where the output latched) and event rows of one record.
fn collect(
    plot: &mut Option<PlotData>,
    events: &mut String,
    want: bool,
    sample_rate_hz: f64,
    e: &ReplayEvent<'_>,
) {
    if let Some(p) = plot {
        p.points.push(point(e));
    }
    if let Some(ev) = &e.alarm.event {
        if let Some(p) = plot {
            p.alarms.push(latched_time_s(e.time_s, ev, sample_rate_hz));
        }
        if want {
            events.push_str(&alarm_row(e, ev, sample_rate_hz));
        }
    }
}

fn point(e: &ReplayEvent<'_>) -> PlotPoint {
    PlotPoint {
        time_s: e.time_s,
        record: *e.record,
        truth: *e.truth,
    }
}

/// A progress bar on stderr over `total_bytes` of input, only when stderr is a terminal
/// and the input is large enough to wait for (over 4 MiB).
pub fn progress_bar(total_bytes: Option<u64>) -> Option<ProgressBar> {
    let total = total_bytes?;
    if total < 4 << 20 || !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = ProgressBar::new(total);
    if let Ok(style) =
        ProgressStyle::with_template("replay {bar:40} {bytes}/{total_bytes} {elapsed} (eta {eta})")
    {
        pb.set_style(style);
    }
    Some(pb)
}

// ---------------------------------------------------------------------------------------
// Machine file
// ---------------------------------------------------------------------------------------

/// A monitor configuration and which keys its file set.
#[derive(Clone, Debug)]
pub struct LoadedConfig {
    /// The configuration: defaults, the file laid over them, the trace's sample rate.
    pub config: MonitorConfig,
    /// The `[alarms]` table laid over the default detectors.
    pub alarms: AlarmConfig,
    /// The `[front_end]` table laid over the default front end, validated (the firmware's
    /// input scaling; replay does not use it).
    pub front_end: FrontEnd,
    /// What names it in messages (the file, or "default configuration").
    pub what: String,
    patch: toml::Table,
}

impl LoadedConfig {
    /// Whether the file gave the key at this dotted path (`["estimator", "tool", "flutes"]`).
    pub fn sets(&self, path: &[&str]) -> bool {
        let mut t = &self.patch;
        for (i, key) in path.iter().enumerate() {
            match t.get(*key) {
                None => return false,
                Some(_) if i + 1 == path.len() => return true,
                Some(toml::Value::Table(sub)) => t = sub,
                Some(_) => return false,
            }
        }
        true
    }

    /// Applies a dynamometer recording's options: dynamometer input and its flute count,
    /// unless the file says otherwise (then an error: the two would disagree).
    pub fn apply_kistler(&mut self, opts: &KistlerOptions) -> Result<()> {
        let what = &self.what;
        if self.sets(&["input"]) && self.config.input != Input::Dynamometer {
            bail!("{what}: a dynamometer recording needs `input = \"dynamometer\"`");
        }
        self.config.input = Input::Dynamometer;
        let flutes = self.config.estimator.tool.flutes;
        if self.sets(&["estimator", "tool", "flutes"]) && flutes != opts.flutes {
            bail!(
                "{what}: estimator.tool.flutes = {flutes}, but the recording's options say {}",
                opts.flutes
            );
        }
        self.config.estimator.tool.flutes = opts.flutes;
        Ok(())
    }
}

/// Reads a machine file (or none: the defaults) for a trace sampled at `trace_rate_hz`.
/// Without `sample_rate_hz` in the file the trace's rate is used; with it, it must match.
pub fn load_monitor_config(
    path: Option<&Path>,
    trace_rate_hz: Option<f64>,
) -> Result<LoadedConfig> {
    match path {
        None => parse_monitor_config("", "default configuration", trace_rate_hz),
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| anyhow!("cannot read {}: {e}", p.display()))?;
            parse_monitor_config(&text, &p.display().to_string(), trace_rate_hz)
        }
    }
}

/// [`load_monitor_config`] from text; `file` names it in messages.
pub fn parse_monitor_config(
    text: &str,
    file: &str,
    trace_rate_hz: Option<f64>,
) -> Result<LoadedConfig> {
    let mut patch: toml::Table = config::parse_toml(text, file)?;
    // `[alarms]` is the AlarmConfig part of the machine, `[front_end]` the FrontEnd part;
    // the rest is the MonitorConfig.
    let split = patch.contains_key("alarms") || patch.contains_key("front_end");
    let alarms: AlarmConfig = take_table(&mut patch, "alarms", file)?;
    let front_end: FrontEnd = take_table(&mut patch, "front_end", file)?;
    front_end
        .validate()
        .map_err(|e| anyhow!("{file} [front_end]: {e}"))?;
    // Without those tables the file's own text is parsed, so TOML errors keep its lines.
    let rest;
    let text = if split {
        rest = toml::to_string(&patch).map_err(|e| anyhow!("{file}: {e}"))?;
        rest.as_str()
    } else {
        text
    };
    let mut base = MonitorConfig::default();
    let wants_load = patch
        .get("input")
        .and_then(|v| v.get("motor"))
        .and_then(|v| v.get("spindle"))
        .and_then(|v| v.get("load"))
        .is_some();
    if wants_load {
        if let Input::Motor { spindle, .. } = &mut base.input {
            *spindle = SpindleModel::paper003();
        }
    }
    let mut cfg: MonitorConfig = config::override_from(&base, text, file)?;
    let gives_rate = patch.contains_key("sample_rate_hz");
    match (gives_rate, trace_rate_hz) {
        (false, Some(r)) => cfg.sample_rate_hz = r as f32,
        (false, None) => bail!(
            "{file}: the trace does not tell its sample rate (no `# sample_rate_hz = ...` line, \
             fewer than two rows); set sample_rate_hz"
        ),
        (true, Some(r)) if (f64::from(cfg.sample_rate_hz) - r).abs() > RATE_TOL * r => bail!(
            "{file}: sample_rate_hz = {}, but the trace is sampled at {r} Hz",
            cfg.sample_rate_hz
        ),
        (true, _) => {}
    }
    Ok(LoadedConfig {
        config: cfg,
        alarms,
        front_end,
        what: file.to_string(),
        patch,
    })
}

/// Removes the table `key` from `patch` and lays it over `T::default()` (the default
/// without it).
fn take_table<T>(patch: &mut toml::Table, key: &str, file: &str) -> Result<T>
where
    T: Default + serde::Serialize + serde::de::DeserializeOwned,
{
    match patch.remove(key) {
        None => Ok(T::default()),
        Some(toml::Value::Table(t)) => {
            let text = toml::to_string(&t).map_err(|e| anyhow!("{file}: [{key}]: {e}"))?;
            config::override_from(&T::default(), &text, &format!("{file} [{key}]"))
        }
        Some(_) => bail!("{file}: `{key}` must be a table ([{key}])"),
    }
}

/// The example machine file committed as host-sim/examples/machine.toml.
pub const MACHINE_EXAMPLE: &str = include_str!("../examples/machine.toml");

// ---------------------------------------------------------------------------------------
// Throughput benchmark
// ---------------------------------------------------------------------------------------

/// What `bench-replay` measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchReport {
    /// Trace length [s] of signal.
    pub seconds: f64,
    /// Samples in the trace.
    pub samples: u64,
    /// Bytes of the trace file.
    pub bytes: u64,
    /// Tooth records.
    pub records: u64,
    /// Wall time of parse + Monitor (a full `replay` minus output) [s].
    pub replay_s: f64,
    /// Wall time of the Monitor alone over samples in memory [s].
    pub monitor_s: f64,
}

impl BenchReport {
    /// Signal seconds per wall second, parse included.
    pub fn replay_x(&self) -> f64 {
        self.seconds / self.replay_s
    }
    /// Signal seconds per wall second, Monitor only.
    pub fn monitor_x(&self) -> f64 {
        self.seconds / self.monitor_s
    }
}

/// Sample rate of the benchmark trace [Hz].
pub const BENCH_RATE_HZ: f64 = 20_000.0;

/// The benchmark's configuration: two-axis motor drive at a nominal feed (the trace has
/// no velocity columns), the paper's tool at 3000 rpm, 20 kS/s.
pub fn bench_config() -> MonitorConfig {
    use estimator_core::drive::FeedDrive;
    let mut cfg = MonitorConfig {
        sample_rate_hz: BENCH_RATE_HZ as f32,
        feed_velocity: FeedVelocity::Nominal([1039.23, 600.0]),
        ..MonitorConfig::default()
    };
    if let Input::Motor { feed, .. } = &mut cfg.input {
        *feed = FeedDrive {
            two_axis: true,
            ..FeedDrive::default()
        };
    }
    cfg
}

/// Writes the benchmark trace: `seconds` of a steady cut (R_r 0.5, R_a 1, t_c 0.1 mm at
/// 3000 rpm, 4 flutes, feed 1200 mm/min at 30 degrees) in three channels, `feed_x_a`,
/// `feed_y_a`, `spindle_a`, with a tooth-frequency ripple and 1 % noise so the numbers
/// have all their digits, as a real ADC's do.
pub fn write_bench_trace(w: impl Write, seconds: f64) -> Result<u64> {
    use estimator_core::{average_forces, Engagement, MillingMode, Tool, TABLE2};
    let cfg = bench_config();
    let Input::Motor { feed, spindle } = &cfg.input else {
        bail!("bench config is a motor config");
    };
    let rpm = 3000.0f32;
    let v = match cfg.feed_velocity {
        FeedVelocity::Nominal(v) => v,
        FeedVelocity::Measured => [0.0; 2],
    };
    let speed = v[0].hypot(v[1]);
    let tool = Tool::PAPER;
    let f = average_forces(
        &tool,
        &TABLE2,
        MillingMode::Down,
        Engagement {
            rr: 0.5,
            ra: 1.0,
            tc_mm: speed / (tool.flutes as f32 * rpm),
        },
    );
    // F_ax along the feed, F_ay across it: the projection keeps F_ax only.
    let u = [v[0] / speed, v[1] / speed];
    let loads = [f.fx_n * u[0] - f.fy_n * u[1], f.fx_n * u[1] + f.fy_n * u[0]];
    let i_feed = feed.currents_for_loads_a(loads, v);
    let i_spindle = spindle.signal_for_force(f.ft_n, rpm, tool.radius_mm);
    let kind = TraceKind {
        feed: FeedSignal::Current,
        two_axis: true,
        has_velocity: false,
        spindle: SpindleSignal::Current,
        has_truth: false,
    };
    let mut wr = TraceWriter::new(w, kind, BENCH_RATE_HZ)?;
    let period = (BENCH_RATE_HZ * 60.0 / (f64::from(rpm) * f64::from(tool.flutes))).round() as u64;
    let n = (seconds * BENCH_RATE_HZ).round() as u64;
    let mut lcg: u32 = 0x1234_5678;
    let mut noise = || {
        lcg = lcg.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (lcg >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
    };
    for k in 0..n {
        let phase = (k % period) as f32 / period as f32 * std::f32::consts::TAU;
        let ripple = 1.0 + 0.5 * phase.sin();
        let row = TraceRow {
            time_s: k as f64 / BENCH_RATE_HZ,
            sync: k % period == 0,
            feed: [
                i_feed[0] * ripple * (1.0 + 0.01 * noise()),
                i_feed[1] * ripple * (1.0 + 0.01 * noise()),
            ],
            feed_velocity_mm_min: v,
            spindle: i_spindle * ripple * (1.0 + 0.01 * noise()),
            truth: Truth::default(),
        };
        wr.write_row(&row)?;
    }
    wr.finish()?;
    Ok(n)
}

/// Writes a `seconds`-long benchmark trace into `dir`, times a replay of it (parse +
/// Monitor, records discarded) and the Monitor alone over the same samples in memory, each
/// `repeat` times keeping the fastest (the least disturbed by other load), and deletes the
/// file.
pub fn bench_replay(seconds: f64, repeat: u32, dir: &Path) -> Result<BenchReport> {
    if !(seconds.is_finite() && seconds > 0.0) {
        bail!("--seconds must be positive");
    }
    let path = dir.join(format!("host-sim-bench-{}.csv", std::process::id()));
    let result = bench_file(seconds, repeat.max(1), &path);
    // Best effort: the measurement (or its error) matters more than a leftover file.
    let _ = std::fs::remove_file(&path);
    result
}

fn bench_file(seconds: f64, repeat: u32, path: &Path) -> Result<BenchReport> {
    {
        let f = std::fs::File::create(path)
            .map_err(|e| anyhow!("cannot create {}: {e}", path.display()))?;
        write_bench_trace(std::io::BufWriter::new(f), seconds)?;
    }
    let bytes = std::fs::metadata(path)?.len();
    let cfg = bench_config();
    let mut replay_s = f64::INFINITY;
    let mut summary = ReplaySummary::default();
    let mut records = 0u64;
    for _ in 0..repeat {
        // Parse + Monitor: the replay loop with a callback that only counts.
        let start = Instant::now();
        let mut rd = TraceReader::open(path)?;
        records = 0;
        summary = replay_source(&mut rd, &cfg, &AlarmConfig::default(), None, |e| {
            records += u64::from(e.record.status.is_valid());
            Ok(())
        })?;
        replay_s = replay_s.min(start.elapsed().as_secs_f64());
    }
    // Monitor alone over the samples in memory.
    let mut rd = TraceReader::open(path)?;
    let mut samples = Vec::with_capacity(summary.samples as usize);
    while let Some(row) = rd.next_row()? {
        samples.push(row.to_sample());
    }
    let monitor = cfg
        .build()
        .map_err(|e| anyhow!("monitor configuration: {e}"))?;
    let mut monitor_s = f64::INFINITY;
    for _ in 0..repeat {
        let start = Instant::now();
        let mut st = estimator_core::MonitorState::default();
        let mut count = 0u64;
        for s in &samples {
            if let Some(r) = monitor.process(&mut st, std::hint::black_box(s)) {
                count += u64::from(std::hint::black_box(r).status.is_valid());
            }
        }
        monitor_s = monitor_s.min(start.elapsed().as_secs_f64());
        if count != records {
            bail!("the two passes disagree: {records} vs {count} valid records");
        }
    }
    Ok(BenchReport {
        seconds: summary.duration_s(),
        samples: summary.samples,
        bytes,
        records: summary.records,
        replay_s,
        monitor_s,
    })
}

// ---------------------------------------------------------------------------------------
// Command line
// ---------------------------------------------------------------------------------------

/// Shown after `host-sim replay --help`.
pub const REPLAY_HELP: &str = "\
INPUT: a raw trace CSV (docs/formats.md, \"Raw trace CSV\"): time_s, sync, feed currents or
forces, optional velocities, spindle signal, optional true_* columns. Or, with --kistler, a
Kistler DynoWare export (Time, Fx, Fy, Fz): tooth pulses are then derived from --rpm and
--flutes, the feed velocity is --feed-mm-min, and the input is a dynamometer.

CONFIG: a TOML MonitorConfig laid over the defaults, with the alarm detectors in an optional
[alarms] table and the board's input scaling in an optional [front_end] table (checked, not
used by replay) (every key optional, unknown keys are errors); example:
host-sim/examples/machine.toml. Without sample_rate_hz the trace's rate is
used. A trace without velocity columns needs feed_velocity = { nominal = [vx, vy] }.

OUTPUT: one row per tooth period (docs/formats.md, \"Per-tooth records CSV\"), or with --bits
one line per record, `idx w0 w1 ...` (8 hex digits per word of ToothRecord::to_words, the
line format of tests/target-check). A summary goes to stderr, with error statistics of d_r
and d_a against the truth when the trace has it.

EXAMPLE (the Kistler recordings under shared/data, X and Y swapped by the setup, forces on the
workpiece):
  host-sim replay --kistler --rpm 6000 --flutes 2 --feed-mm-min 600 --feed-axis=-y \\
      --normal-axis=-x --trace n6000f600ap3ae25.csv --output records.csv --plot records.png";

/// Arguments of `host-sim replay`.
#[derive(clap::Args, Debug, Clone)]
pub struct ReplayArgs {
    /// Raw trace CSV, or a DynoWare export with --kistler.
    #[arg(long, value_name = "FILE")]
    pub trace: PathBuf,
    /// Machine file (TOML MonitorConfig) over the defaults.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Per-tooth records to write; default: standard output.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Plot of the records over time (.png or .svg).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Write each record as `idx` and its raw words in hex instead of CSV.
    #[arg(long)]
    pub bits: bool,
    /// Alarm events CSV to write (time_s, latched_s, record, tooth, cause, value,
    /// threshold, latched).
    #[arg(long, value_name = "FILE")]
    pub alarms: Option<PathBuf>,
    /// Options of a dynamometer recording.
    #[command(flatten)]
    pub kistler: KistlerArgs,
}

/// `replay`'s options for a Kistler DynoWare export.
#[derive(clap::Args, Debug, Clone)]
pub struct KistlerArgs {
    /// The trace is a Kistler DynoWare export (needs --rpm, --flutes, --feed-mm-min).
    #[arg(long)]
    pub kistler: bool,
    /// Nominal spindle speed [rpm].
    #[arg(long, requires = "kistler", value_name = "RPM")]
    pub rpm: Option<f64>,
    /// Flutes of the cutter.
    #[arg(long, requires = "kistler", value_name = "N")]
    pub flutes: Option<u8>,
    /// Nominal feed [mm/min].
    #[arg(long, requires = "kistler", value_name = "MM_MIN")]
    pub feed_mm_min: Option<f64>,
    /// Time of one tooth pulse [s], file time base; the others follow every tooth period.
    #[arg(
        long,
        default_value_t = 0.0,
        allow_negative_numbers = true,
        value_name = "S"
    )]
    pub sync_phase: f64,
    /// Dynamometer axis along the feed: x, -x, y, -y (write --feed-axis=-y).
    #[arg(
        long,
        default_value = "x",
        allow_hyphen_values = true,
        value_name = "AXIS"
    )]
    pub feed_axis: Axis,
    /// Dynamometer axis normal to the feed.
    #[arg(
        long,
        default_value = "y",
        allow_hyphen_values = true,
        value_name = "AXIS"
    )]
    pub normal_axis: Axis,
}

impl KistlerArgs {
    /// The recording's options, `None` without --kistler.
    pub fn options(&self) -> Result<Option<KistlerOptions>> {
        if !self.kistler {
            return Ok(None);
        }
        let need = |v: Option<f64>, flag: &str| v.ok_or_else(|| anyhow!("--kistler needs {flag}"));
        let flutes = self
            .flutes
            .ok_or_else(|| anyhow!("--kistler needs --flutes"))?;
        let o = KistlerOptions {
            rpm: need(self.rpm, "--rpm")?,
            flutes,
            feed_mm_min: need(self.feed_mm_min, "--feed-mm-min")?,
            sync_phase_s: self.sync_phase,
            feed_axis: self.feed_axis,
            normal_axis: self.normal_axis,
        };
        o.validate()?;
        Ok(Some(o))
    }
}

/// Opens the trace of `args` (raw trace or DynoWare export) and loads its configuration,
/// checked (a `ConfigError` is reported against the machine file).
pub fn open_replay(args: &ReplayArgs) -> Result<(Box<dyn RowSource>, LoadedConfig)> {
    let kistler = args.kistler.options()?;
    let mut src: Box<dyn RowSource> = match &kistler {
        Some(o) => Box::new(KistlerReader::open(&args.trace, *o)?),
        None => Box::new(TraceReader::open(&args.trace)?),
    };
    let rate = src.detect_sample_rate_hz()?;
    let mut loaded = load_monitor_config(args.config.as_deref(), rate)?;
    if let Some(o) = &kistler {
        loaded.apply_kistler(o)?;
    }
    MachineConfig {
        monitor: loaded.config.clone(),
        alarms: loaded.alarms,
        front_end: loaded.front_end,
    }
    .build()
    .map_err(|e| anyhow!("{}: {e}", loaded.what))?;
    check_compatible(&src.kind(), &loaded.config, src.name())
        .map_err(|e| anyhow!("{e} ({})", loaded.what))?;
    Ok((src, loaded))
}
