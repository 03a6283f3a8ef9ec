//! `demo`: the whole product on one simulated cut, with no files to supply.
//!
//! # Design
//! 1. The scenario is [`SCENARIO_TEXT`], host-sim/examples/cut.toml compiled in (an entry
//!    through the work's face, a radial-depth ramp, an axial step, a feed change, then a
//!    flute breaking and the exit); `--scenario` runs a copy of it instead.
//! 2. [`machine_for`] gives the monitor the scenario's board: its `input` (drive and
//!    spindle models), tool, coefficients, milling mode, sync mode, sample rate and the
//!    ADC's clip levels ([`crate::sim::clip_levels`]); alarms at their defaults.
//! 3. [`crate::sim::write_trace`] writes the raw trace CSV into the output directory, and
//!    [`crate::replay::replay_to`] replays that file, exactly as `host-sim replay --trace
//!    trace.csv --config machine.toml` does (the demo writes both, so the replay can be
//!    repeated by hand). Memory stays flat: the trace streams through a file; only the
//!    per-tooth records (a few hundred) are kept, for the plot and the table.
//! 4. The table ([`SegmentRow`]): per `[[segment]]`, the truth and the estimates over the
//!    tooth periods that end inside it. The alarm line uses the first latching alarm of
//!    [`ReplaySummary::first_alarm`] and the scenario's own damage event for the latency.
//!
//! Files written (each through a `.partial` file renamed when complete): `trace.csv`,
//! `records.csv`, `alarms.csv`, `machine.toml`, `demo.png`.

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::alarm::AlarmConfig;
use estimator_core::monitor::FeedVelocity;
use estimator_core::{EstimatorConfig, MachineConfig, MonitorConfig};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::plot::{self, PlotData, PlotFormat, PlotPoint};
use crate::replay::{self, RecordFormat, ReplayOutputs, ReplaySummary};
use crate::sim::scenario::Coefficients;
use crate::sim::{self, EventKind, Scenario, SimSummary};
use crate::trace::TraceReader;

/// The demo's scenario: host-sim/examples/cut.toml, compiled in.
pub const SCENARIO_TEXT: &str = include_str!("../examples/cut.toml");
/// Where [`SCENARIO_TEXT`] lives in the repository (to copy and edit).
pub const SCENARIO_PATH: &str = "host-sim/examples/cut.toml";

/// Largest relative error of a steady segment's mean estimate that the tests accept.
pub const STEADY_TOLERANCE: f64 = 0.05;

/// Shown after `host-sim demo --help`.
pub const DEMO_HELP: &str = "\
WHAT IT DOES: simulates the cut of host-sim/examples/cut.toml (compiled in: the paper's 16 mm
four-flute end mill in steel at 600 rpm; entry through the work's face, a radial-depth ramp
4 -> 8 mm, an axial step 4 -> 6 mm met over a tool radius of travel, a feed change
0.15 -> 0.225 mm/tooth, flute 2 breaking at 11.49 s, the exit), with motor-current noise,
current-loop lag, 12-bit ADCs and encoder jitter; replays the trace through the same
Pipeline the firmware runs (monitor + alarms), configured for the simulated board; and
prints, per segment of the scenario, the true and the estimated radial and axial depths of
cut, and the alarm with its latency after the break.

FILES (in --out-dir, default target/demo/ of this checkout):
  trace.csv     the raw trace (docs/formats.md, \"Raw trace CSV\")
  records.csv   one row per tooth period (docs/formats.md, \"Per-tooth records CSV\")
  alarms.csv    the alarm events
  machine.toml  the monitor configuration used: `host-sim replay --trace trace.csv
                --config machine.toml` repeats the replay
  demo.png      forces, d_r, d_a with their ±2 sigma bands and the truth, status, alarms

To try another cut, copy host-sim/examples/cut.toml, edit it and pass --scenario.";

/// Arguments of `host-sim demo`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct DemoArgs {
    /// Directory for the trace, records, alarms, machine file and plot; default:
    /// target/demo/ of this checkout.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Scenario to run instead of the built-in host-sim/examples/cut.toml.
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
}

/// The built-in scenario, parsed.
pub fn builtin_scenario() -> Result<Scenario> {
    Scenario::from_toml(SCENARIO_TEXT, SCENARIO_PATH)
}

/// `target/demo` of the workspace this binary was built from.
pub fn default_out_dir() -> PathBuf {
    let host_sim = Path::new(env!("CARGO_MANIFEST_DIR"));
    host_sim
        .parent()
        .unwrap_or(host_sim)
        .join("target")
        .join("demo")
}

/// The monitor configuration that matches the scenario's board: its input models, tool,
/// power-law coefficients, milling mode, sync mode, sample rate and ADC clip levels; the
/// other settings and the alarms at their defaults. The monitor has one milling mode, the
/// scenario's top-level `mode`: a segment that sets its own is estimated with the other.
pub fn machine_for(sc: &Scenario) -> Result<MachineConfig> {
    let coeffs = match sc.material.coefficients() {
        Coefficients::PowerLaw(c) => c,
        Coefficients::Linear(_) => bail!(
            "the estimator inverts power-law coefficients (eq. 9); this scenario's material \
             is linear: use `material = \"table2\"` or a [material.power_law] table"
        ),
    };
    if !sc.output.velocity {
        bail!(
            "the demo's monitor measures the feed velocity: the scenario needs \
             [output] velocity = true"
        );
    }
    Ok(MachineConfig {
        monitor: MonitorConfig {
            sample_rate_hz: sc.sample_rate_hz as f32,
            input: sc.input.clone(),
            feed_velocity: FeedVelocity::Measured,
            estimator: EstimatorConfig {
                tool: sc.tool.core(),
                coeffs,
                mode: sc.mode,
                ..EstimatorConfig::default()
            },
            sync: sc.sync,
            clip: sim::clip_levels(sc).map(|c| c as f32),
            ..MonitorConfig::default()
        },
        alarms: AlarmConfig::default(),
        front_end: estimator_core::FrontEnd::default(),
    })
}

/// The machine file of `replay --config`: the MonitorConfig's keys at the top, the
/// detectors in `[alarms]`.
pub fn machine_file(machine: &MachineConfig) -> Result<String> {
    #[derive(serde::Serialize)]
    struct Alarms<'a> {
        alarms: &'a AlarmConfig,
    }
    let err = |e: toml::ser::Error| anyhow!("serialising the machine file: {e}");
    let monitor = toml::to_string(&machine.monitor).map_err(err)?;
    let alarms = toml::to_string(&Alarms {
        alarms: &machine.alarms,
    })
    .map_err(err)?;
    Ok(format!("{monitor}\n{alarms}"))
}

/// One line of the table: a `[[segment]]` of the scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentRow {
    /// The segment's label (or `segment N`).
    pub label: String,
    /// Start [s].
    pub t0: f64,
    /// End [s].
    pub t1: f64,
    /// Constant programmed speed, feed, `d_r` and `d_a`, the tool in the work throughout,
    /// no damage event: the estimates should equal the truth once the filter settles.
    pub steady: bool,
    /// Tooth records ending in the segment.
    pub records: u64,
    /// Those that are valid.
    pub valid: u64,
    /// Mean true `d_r` over the records in the work (air excluded) [mm]; NaN if none.
    pub true_dr_mm: f64,
    /// Mean true `d_a` over the same records [mm].
    pub true_da_mm: f64,
    /// Mean estimated `d_r` over the valid records [mm]; NaN if none.
    pub est_dr_mm: f64,
    /// Mean estimated `d_a` over the valid records [mm].
    pub est_da_mm: f64,
    /// Mean of the valid records' `2 sigma` of `d_r` [mm].
    pub dr_2sigma_mm: f64,
    /// Mean of the valid records' `2 sigma` of `d_a` [mm].
    pub da_2sigma_mm: f64,
    /// Mean relative error of the valid records' `d_r` against the truth averaged over the
    /// teeth each one's filter window holds (replay's comparison; a mean over a ramp is
    /// not comparable with the segment's mean truth); NaN if none.
    pub dr_err: f64,
    /// The same for `d_a`.
    pub da_err: f64,
}

impl SegmentRow {
    /// Share of the segment's records that are valid (NaN for none).
    pub fn valid_share(&self) -> f64 {
        self.valid as f64 / self.records as f64
    }

    /// Relative errors of the mean estimates, `(d_r, d_a)`.
    pub fn rel_errors(&self) -> (f64, f64) {
        (
            self.est_dr_mm / self.true_dr_mm - 1.0,
            self.est_da_mm / self.true_da_mm - 1.0,
        )
    }
}

/// The first damage of the scenario's timeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Damage {
    /// When [s].
    pub time_s: f64,
    /// Which flute.
    pub flute: u8,
    /// Break or chip.
    pub kind: EventKind,
}

/// Where the demo wrote its files.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoFiles {
    /// Raw trace CSV.
    pub trace: PathBuf,
    /// Per-tooth records CSV.
    pub records: PathBuf,
    /// Alarm events CSV.
    pub alarms: PathBuf,
    /// The machine file used.
    pub machine: PathBuf,
    /// The plot (PNG).
    pub plot: PathBuf,
}

/// What a demo run did.
#[derive(Clone, Debug)]
pub struct DemoReport {
    /// The scenario's name (file).
    pub scenario: String,
    /// The simulator's summary.
    pub sim: SimSummary,
    /// The replay's summary (counts, errors against the truth, first alarm).
    pub replay: ReplaySummary,
    /// One row per segment.
    pub segments: Vec<SegmentRow>,
    /// The scenario's first damage event.
    pub damage: Option<Damage>,
    /// The configuration the replay ran.
    pub machine: MachineConfig,
    /// Files written.
    pub files: DemoFiles,
    /// Wall time [s].
    pub elapsed_s: f64,
}

impl DemoReport {
    /// Time from the scenario's first damage event to the first latching alarm [s].
    pub fn alarm_latency_s(&self) -> Option<f64> {
        Some(self.replay.first_alarm?.latched_s - self.damage?.time_s)
    }

    /// The table, the alarm and the files, as printed.
    pub fn text(&self) -> String {
        let mut s = String::new();
        let sim = &self.sim;
        let r = &self.replay;
        let _ = writeln!(
            s,
            "{}: {:.1} s of cutting simulated at {} Hz ({} samples, {} sync pulses, {} lost) and \
             replayed: {} tooth records, {} valid ({:.1} s)",
            self.scenario,
            sim.duration_s,
            r.sample_rate_hz,
            sim.rows,
            sim.sync_pulses,
            sim.sync_dropped,
            r.records,
            r.valid,
            self.elapsed_s
        );
        s.push('\n');
        let w = self
            .segments
            .iter()
            .map(|g| g.label.chars().count())
            .max()
            .unwrap_or(0)
            .max(7);
        let _ = writeln!(
            s,
            "{:<w$}  {:>10}  {:>5} {:>14} {:>7}  {:>5} {:>14} {:>7}  {:>5}",
            "segment",
            "time [s]",
            "d_r",
            "estimate ±2σ",
            "err",
            "d_a",
            "estimate ±2σ",
            "err",
            "valid"
        );
        let num = |v: f64, f: &dyn Fn(f64) -> String| {
            if v.is_nan() {
                "-".to_string()
            } else {
                f(v)
            }
        };
        for g in &self.segments {
            let est = |v: f64, band: f64| num(v, &|v| format!("{v:.3} ± {band:.3}"));
            let truth = |v: f64| num(v, &|v| format!("{v:.2}"));
            let err = |v: f64| num(v, &|v| format!("{:+.2}%", 100.0 * v));
            let _ = writeln!(
                s,
                "{:<w$}  {:>10}  {:>5} {:>14} {:>7}  {:>5} {:>14} {:>7}  {:>4.0}%",
                g.label,
                format!("{:.1}-{:.1}", g.t0, g.t1),
                truth(g.true_dr_mm),
                est(g.est_dr_mm, g.dr_2sigma_mm),
                err(g.dr_err),
                truth(g.true_da_mm),
                est(g.est_da_mm, g.da_2sigma_mm),
                err(g.da_err),
                100.0 * g.valid_share()
            );
        }
        let _ = writeln!(
            s,
            "Depths in mm. d_r, d_a: the simulator's truth, mean over the segment's tooth periods in the\n\
             work. estimate: mean over the valid records, ±2σ their mean uncertainty. err: mean error of\n\
             the valid records against the truth over each one's filter window ({} revolutions).\n\
             valid: share of the segment's records the monitor marks valid (ramps, steps and feed\n\
             changes are flagged transient until the filter settles).",
            self.machine.monitor.filter_revs
        );
        s.push('\n');
        s += &self.alarm_text();
        s.push('\n');
        let files = &self.files;
        let _ = writeln!(
            s,
            "wrote {}, {}, {}, {}, {}",
            shown(&files.plot),
            shown(&files.records),
            shown(&files.trace),
            shown(&files.alarms),
            shown(&files.machine)
        );
        let _ = writeln!(
            s,
            "replay it: host-sim replay --trace {} --config {}",
            shown(&files.trace),
            shown(&files.machine)
        );
        s
    }

    fn alarm_text(&self) -> String {
        let r = &self.replay;
        let what = |d: &Damage| match d.kind {
            EventKind::Break => format!("flute {} broke at {:.3} s", d.flute, d.time_s),
            EventKind::Chip => format!("flute {} chipped at {:.3} s", d.flute, d.time_s),
        };
        let mut s = match (&r.first_alarm, &self.damage) {
            (Some(a), damage) => {
                let rec = &a.event.record;
                let mut s = format!(
                    "alarm: {} at {:.3} s (record {}, tooth {}; force {:.1} N against a \
                     threshold of {:.1} N)",
                    a.event.cause.name(),
                    a.latched_s,
                    a.index,
                    rec.tooth,
                    a.event.value,
                    a.event.threshold
                );
                if a.latched_s < a.time_s {
                    let _ = write!(
                        s,
                        "\n  the output latched at a drop trip inside a period; record {} at \
                         {:.3} s named the cause",
                        a.index, a.time_s
                    );
                }
                match damage {
                    Some(d) if a.latched_s >= d.time_s => {
                        let l = a.latched_s - d.time_s;
                        let rev_s = 60.0 / f64::from(rec.rpm);
                        let tooth_s = f64::from(rec.samples) / r.sample_rate_hz;
                        let _ = write!(
                            s,
                            "\n  {:.1} ms after {}: {:.1} teeth, {:.2} revolution",
                            1e3 * l,
                            what(d),
                            l / tooth_s,
                            l / rev_s
                        );
                        if let Some(ls) = a.latency_s {
                            let _ = write!(
                                s,
                                "\n  ({:.1} ms after the first tooth period to end with the damage)",
                                1e3 * ls
                            );
                        }
                    }
                    Some(d) => {
                        let _ = write!(s, "\n  before {}: a false alarm", what(d));
                    }
                    None => s.push_str("\n  the scenario damages no flute: a false alarm"),
                }
                s
            }
            (None, Some(d)) => format!("no alarm, but {}", what(d)),
            (None, None) => "no alarm (and no damage in the scenario)".to_string(),
        };
        s.push('\n');
        s
    }
}

/// `path` relative to the current directory when it lies below it.
fn shown(path: &Path) -> String {
    std::env::current_dir()
        .ok()
        .and_then(|cwd| path.strip_prefix(cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| path.to_path_buf())
        .display()
        .to_string()
}

/// Writes `path` through `path.partial`, renamed only when `body` succeeded: a failed run
/// never leaves a truncated output that looks complete. Every output of host-sim goes
/// through it.
pub fn write_then_rename<T>(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> Result<T>,
) -> Result<T> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    let tmp = PathBuf::from(tmp);
    let f = File::create(&tmp).with_context(|| format!("cannot create {}", tmp.display()))?;
    let mut w = BufWriter::new(f);
    let result = body(&mut w).and_then(|v| {
        w.flush()
            .with_context(|| format!("cannot write {}", tmp.display()))?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot rename {} to {}", tmp.display(), path.display()))?;
        Ok(v)
    });
    if result.is_err() {
        // Best effort: the error being reported matters more than a leftover file.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The truth each record's estimate is compared with: the mean `(d_r, d_a)` of the truth
/// over the last `window` tooth periods the Monitor averaged (an air cut empties it), as
/// replay's error statistics do.
fn window_truths(points: &[PlotPoint], window: usize) -> Vec<(f64, f64)> {
    use estimator_core::Status;
    let window = window.max(1);
    let mut recent: std::collections::VecDeque<(f64, f64)> = Default::default();
    points
        .iter()
        .map(|p| {
            let st = p.record.status;
            if st.contains(Status::NOT_CUTTING) {
                recent.clear();
            } else if !st
                .intersects(Status::PERIOD_INVALID | Status::INPUT_FAULT | Status::NON_FINITE)
            {
                if recent.len() == window {
                    recent.pop_front();
                }
                recent.push_back((f64::from(p.truth.dr_mm), f64::from(p.truth.da_mm)));
            }
            let n = recent.len() as f64;
            let (a, b) = recent
                .iter()
                .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
            (a / n, b / n)
        })
        .collect()
}

/// The table's rows from the replayed records; `window` is the Monitor's filter length in
/// tooth periods (`filter_revs x flutes`).
pub fn segment_rows(sc: &Scenario, points: &[PlotPoint], window: usize) -> Result<Vec<SegmentRow>> {
    let segs = sc.resolve()?;
    let end = segs.last().map_or(0.0, |g| g.t1);
    let truths = window_truths(points, window);
    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let (n, sum) = v.fold((0u32, 0.0f64), |(n, s), x| (n + 1, s + x));
        sum / f64::from(n) // NaN for none
    };
    let mut rows = Vec::with_capacity(segs.len());
    for (i, (seg, g)) in sc.segments.iter().zip(&segs).enumerate() {
        let last = i + 1 == segs.len();
        let inside: Vec<(&PlotPoint, (f64, f64))> = points
            .iter()
            .zip(truths.iter().copied())
            .filter(|(p, _)| p.time_s >= g.t0 && (p.time_s < g.t1 || (last && p.time_s <= end)))
            .collect();
        let cut: Vec<&PlotPoint> = inside
            .iter()
            .map(|(p, _)| *p)
            .filter(|p| p.truth.dr_mm > 0.0)
            .collect();
        let valid: Vec<(&PlotPoint, (f64, f64))> = inside
            .iter()
            .copied()
            .filter(|(p, _)| p.record.status.is_valid())
            .collect();
        let constant = |(a, b): (f64, f64)| a == b;
        let damaged = sc
            .events
            .iter()
            .any(|e| e.time_s >= g.t0 && e.time_s < g.t1);
        let est = |f: fn(&PlotPoint) -> f32| mean(&mut valid.iter().map(|(p, _)| f64::from(f(p))));
        rows.push(SegmentRow {
            label: seg
                .label
                .clone()
                .unwrap_or_else(|| format!("segment {}", i + 1)),
            t0: g.t0,
            t1: g.t1,
            steady: constant(g.rpm)
                && constant(g.feed)
                && constant(g.dr)
                && constant(g.da)
                && !damaged
                && !inside.is_empty()
                && cut.len() == inside.len(),
            records: inside.len() as u64,
            valid: valid.len() as u64,
            true_dr_mm: mean(&mut cut.iter().map(|p| f64::from(p.truth.dr_mm))),
            true_da_mm: mean(&mut cut.iter().map(|p| f64::from(p.truth.da_mm))),
            est_dr_mm: est(|p| p.record.dr_mm),
            est_da_mm: est(|p| p.record.da_mm),
            dr_2sigma_mm: 2.0 * est(|p| p.record.dr_sigma_mm),
            da_2sigma_mm: 2.0 * est(|p| p.record.da_sigma_mm),
            dr_err: mean(
                &mut valid
                    .iter()
                    .map(|(p, (t, _))| f64::from(p.record.dr_mm) / t - 1.0),
            ),
            da_err: mean(
                &mut valid
                    .iter()
                    .map(|(p, (_, t))| f64::from(p.record.da_mm) / t - 1.0),
            ),
        });
    }
    Ok(rows)
}

/// Runs the demo on `sc` (named `name` in messages) into `out_dir` (created if needed).
pub fn run_demo(sc: &Scenario, name: &str, out_dir: &Path) -> Result<DemoReport> {
    let started = Instant::now();
    if !sc.output.truth {
        bail!("{name}: the demo compares with the truth: set [output] truth = true");
    }
    let machine = machine_for(sc).with_context(|| name.to_string())?;
    machine
        .clone()
        .build()
        .map_err(|e| anyhow!("{name}: the monitor refuses its configuration: {e}"))?;
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("cannot create {}", out_dir.display()))?;
    let files = DemoFiles {
        trace: out_dir.join("trace.csv"),
        records: out_dir.join("records.csv"),
        alarms: out_dir.join("alarms.csv"),
        machine: out_dir.join("machine.toml"),
        plot: out_dir.join("demo.png"),
    };

    // Simulate into the trace file.
    let sim = write_then_rename(&files.trace, |w| Ok(sim::write_trace(sc, w)?.0))
        .with_context(|| format!("simulating {name}"))?;

    // The machine file, then the replay of the trace file with it.
    let toml_text = machine_file(&machine)?;
    write_then_rename(&files.machine, |w| {
        w.write_all(
            format!(
                "# Monitor configuration of `host-sim demo` for {name}: the scenario's board,\n\
                 # tool and sample rate, the ADC's clip levels, the other settings and the alarms\n\
                 # at their defaults. `host-sim replay --trace trace.csv --config machine.toml`.\n\n\
                 {toml_text}"
            )
            .as_bytes(),
        )
        .context("writing the machine file")
    })?;
    let mut reader = TraceReader::open(&files.trace)?;
    let outputs = ReplayOutputs {
        plot: true,
        alarms: machine.alarms,
        events: true,
    };
    let (summary, plot_data, events) = write_then_rename(&files.records, |w| {
        replay::replay_to(
            &mut reader,
            &machine.monitor,
            w,
            RecordFormat::Csv,
            &outputs,
            None,
        )
    })?;
    write_then_rename(&files.alarms, |w| {
        w.write_all(events.as_bytes())
            .context("writing the alarm events")
    })?;
    let mut plot_data: PlotData =
        plot_data.ok_or_else(|| anyhow!("the replay collected no plot data"))?;
    plot_data.title = format!("host-sim demo: {name}");
    let png = plot::render(&plot_data, PlotFormat::Png)?;
    write_then_rename(&files.plot, |w| {
        w.write_all(&png).context("writing the plot")
    })?;

    let window = usize::from(machine.monitor.filter_revs) * usize::from(sc.tool.flutes);
    let segments = segment_rows(sc, &plot_data.points, window)?;
    let damage = sc
        .events
        .iter()
        .min_by(|a, b| a.time_s.total_cmp(&b.time_s))
        .map(|e| Damage {
            time_s: e.time_s,
            flute: e.flute,
            kind: e.kind,
        });
    Ok(DemoReport {
        scenario: name.to_string(),
        sim,
        replay: summary,
        segments,
        damage,
        machine,
        files,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}

/// The `demo` command: the built-in scenario (or `--scenario`), report on stdout.
pub fn run(args: &DemoArgs) -> Result<DemoReport> {
    let (sc, name) = match &args.scenario {
        None => (builtin_scenario()?, SCENARIO_PATH.to_string()),
        Some(p) => {
            let name = p.display().to_string();
            let text = std::fs::read_to_string(p).with_context(|| format!("cannot read {name}"))?;
            (Scenario::from_toml(&text, &name)?, name)
        }
    };
    let out_dir = args.out_dir.clone().unwrap_or_else(default_out_dir);
    let report = run_demo(&sc, &name, &out_dir)?;
    print!("{}", report.text());
    Ok(report)
}
