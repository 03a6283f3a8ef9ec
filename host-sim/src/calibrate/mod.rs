//! `calibrate`: from a few recordings on the user's machine to the constants the board runs
//! with (method.md sections 1-3). Three steps, in this order, each reading the machine file
//! the step before wrote and writing it back with its own constants replaced:
//!
//! 1. [`friction`]: feed-axis offset, Coulomb and viscous friction from air moves;
//! 2. [`spindle`]: the spindle's idle signal against speed from a speed sweep;
//! 3. [`cutting`]: the power laws of eq. 9 (what the estimator runs on) and the linear
//!    shearing / edge coefficients from calibration cuts of known engagement, plus the
//!    `f_xt` polynomial for the new coefficients ([`crate::gen_poly`]); what the laws leave
//!    unexplained becomes the estimator's `gain_uncertainty`.
//!
//! Each step prints a report (every point, the fit, residuals, 95 % intervals) and can
//! write it with a plot (`--report-dir`). The machine file is the one `replay` reads; its
//! `[estimator]` table is also a tool file for `estimate`; the firmware is built from it
//! (`FIRMWARE_MACHINE`, see firmware/build.rs) and from the polynomial
//! (`ESTIMATOR_FXT_POLY`, see estimator-core/build.rs).

pub mod cutting;
pub mod friction;
pub mod spindle;
pub mod stats;

use crate::plot::{render_fits, FitPanel};
use crate::replay::{load_monitor_config, LoadedConfig};
use crate::{gen_poly, write_then_rename};
use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, Subcommand};
use estimator_core::monitor::Input;
use estimator_core::{MillingMode, PowerLaw};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The calibration steps.
#[derive(Subcommand, Debug)]
pub enum CalibrateCmd {
    /// Feed friction from air moves: per axis the current offset, Coulomb and viscous terms.
    #[command(after_help = FRICTION_HELP)]
    Friction {
        /// Machine files in and out, report.
        #[command(flatten)]
        common: Common,
        /// Raw traces of air moves (no cutting), with feed velocity columns.
        #[arg(required = true, value_name = "TRACE")]
        traces: Vec<PathBuf>,
    },
    /// Spindle idle signal against speed from a speed sweep out of the cut.
    #[command(after_help = SPINDLE_HELP)]
    Spindle {
        /// Machine files in and out, report.
        #[command(flatten)]
        common: Common,
        /// Speeds [rpm] where the idle curve breaks (winding switch, ...), comma separated;
        /// default: chosen from the data (one to three lines).
        #[arg(long, value_delimiter = ',', value_name = "RPM")]
        breaks: Option<Vec<f64>>,
        /// Raw traces of the sweep (each speed held a second or more).
        #[arg(required = true, value_name = "TRACE")]
        traces: Vec<PathBuf>,
    },
    /// Cutting coefficients from calibration cuts of known depth.
    #[command(after_help = CUTTING_HELP)]
    Cutting {
        /// Machine files in and out, report.
        #[command(flatten)]
        common: Common,
        /// The cuts (TOML, see below).
        #[arg(long, value_name = "FILE")]
        plan: PathBuf,
        /// Write the f_xt polynomial for the fitted coefficients here (Rust source, for
        /// `ESTIMATOR_FXT_POLY=... cargo build`); default: beside --output as
        /// `<output stem>.fxt_poly.rs`.
        #[arg(long, value_name = "FILE")]
        poly_output: Option<PathBuf>,
        /// Write the linear shearing/edge coefficients as a `[material.linear]` table for
        /// scenario and voxel files; default: beside --output as `<output stem>.linear.toml`.
        #[arg(long, value_name = "FILE")]
        linear_output: Option<PathBuf>,
    },
}

/// What every step takes.
#[derive(Args, Debug)]
pub struct Common {
    /// Machine file to start from (docs/formats.md); default: the built-in defaults.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Machine file to write: the input one with the identified constants replaced.
    #[arg(long, value_name = "FILE")]
    pub output: PathBuf,
    /// Also write the report (`<step>.md`) and its plot (`<step>.svg`) here.
    #[arg(long, value_name = "DIR")]
    pub report_dir: Option<PathBuf>,
}

const FRICTION_HELP: &str = "\
Record air moves (spindle may run, no cutting) on each feed axis at three or more feed
velocities in BOTH directions, each held for a second or more (e.g. G1 X200 F300, G1 X0 F300,
then F1000, F3000). The trace needs feed velocity columns (feed_vx_mm_min: the board's feed
encoder). Steady stretches are found automatically (velocity within 2 %, first quarter of
each dropped). Per axis the fit is  i = i0 + (F_c sgn v + b v) / k_f  with k_f = sign 2 pi
eta K_t / L from the machine file: writes current_offset_a, coulomb_n, viscous_n_per_mm_min.";

const SPINDLE_HELP: &str = "\
Record the spindle out of the cut at a dozen speeds across its range, each held for a second
or more, with the tool in (its idle torque is part of the idle signal). The Monitor measures
speed and per-tooth mean signal; each steady speed is one point. Writes the idle lines of the
spindle model (idle_current_a, or idle_load_pct for a load input), one line per interval
between breaks.";

const CUTTING_HELP: &str = "\
PLAN FILE (TOML; paths relative to it):
  mode = \"down\"                 # default milling mode of the cuts (else the machine file's)
  [[cut]]
  trace = \"slot_f010.csv\"       # a raw trace, replayed with the machine file (friction and
  dr_mm = 16.0                  #   spindle idle calibrated first), steady teeth averaged
  da_mm = 4.0
  from_s = 2.0                  # optional window of the trace [s]
  to_s = 6.0
  [[cut]]
  teeth = \"cut2.csv\"            # or per-tooth averages: tc_mm, fx_n, ft_n (or fy_n) [, fz_n],
                                #   or a records CSV of replay / decode-telemetry (the board's
                                #   own per-tooth output; its status column picks steady teeth)
  dr_mm = 8.0
  da_mm = 4.0
  mode = \"up\"                   # per cut

Each cut holds one feed per tooth. Use at least three feeds across the range you will cut
(the fit's t_c range is written as tc_fit_mm; estimates outside it are flagged), at
R_r >= 0.5 (light cuts make r1 ill-conditioned). Slots at several feeds also give the linear
coefficients as paper 003 does. r2 needs the axial force (fz_n in a per-tooth CSV); without
it r2 is kept from the machine file (the estimator does not use it).";

/// Runs a step.
pub fn run(cmd: &CalibrateCmd) -> Result<()> {
    match cmd {
        CalibrateCmd::Friction { common, traces } => run_friction(common, traces),
        CalibrateCmd::Spindle {
            common,
            breaks,
            traces,
        } => run_spindle(common, breaks.as_deref(), traces),
        CalibrateCmd::Cutting {
            common,
            plan,
            poly_output,
            linear_output,
        } => run_cutting(
            common,
            plan,
            poly_output.as_deref(),
            linear_output.as_deref(),
        ),
    }
}

/// The machine file to start from. Its sample rate is the traces' own (each step reads it
/// from the trace), so a placeholder stands in when the file gives none.
pub fn load_base(path: Option<&Path>) -> Result<LoadedConfig> {
    load_monitor_config(path, Some(20_000.0))
}

/// The machine file as TOML text: the MonitorConfig at the top, `[alarms]`, `[front_end]`.
/// `sample_rate_hz` only if the base file set it (else the replayed trace tells it).
pub fn machine_toml(cfg: &LoadedConfig, header: &str) -> Result<String> {
    let mut t = toml::Table::try_from(&cfg.config).context("serialising the machine file")?;
    if !cfg.sets(&["sample_rate_hz"]) {
        t.remove("sample_rate_hz");
    }
    t.insert(
        "alarms".into(),
        toml::Value::Table(toml::Table::try_from(cfg.alarms).context("serialising [alarms]")?),
    );
    t.insert(
        "front_end".into(),
        toml::Value::Table(
            toml::Table::try_from(cfg.front_end).context("serialising [front_end]")?,
        ),
    );
    let mut v = toml::Value::Table(t);
    short_floats(&mut v);
    let body = toml::to_string(&v).context("writing the machine file")?;
    let mut out = String::new();
    for line in header.lines() {
        let _ = writeln!(out, "# {line}");
    }
    out.push('\n');
    out.push_str(&body);
    Ok(out)
}

/// Every float as the shortest decimal of its f32 (the core's type): `0.02`, not
/// `0.019999999552965164`. Reads back to the same f32.
fn short_floats(v: &mut toml::Value) {
    match v {
        toml::Value::Float(f) if f.is_finite() => {
            *f = format!("{}", *f as f32).parse().unwrap_or(*f);
        }
        toml::Value::Table(t) => t.iter_mut().for_each(|(_, v)| short_floats(v)),
        toml::Value::Array(a) => a.iter_mut().for_each(short_floats),
        _ => {}
    }
}

/// Writes `bytes` to `path` through a temporary file, creating its directory.
fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    write_then_rename(path, |w| w.write_all(bytes).map_err(Into::into))
}

/// Writes the machine file to `output` and checks that `replay` reads back the same
/// configuration; `command` (`calibrate friction`, `teach`) and `inputs` go in its header.
pub(crate) fn write_machine(
    output: &Path,
    cfg: &LoadedConfig,
    command: &str,
    inputs: &[PathBuf],
) -> Result<()> {
    let header = format!(
        "Machine file written by `host-sim {command}` from {} (base: {}).\n\
         Read by `host-sim replay --config`; its [estimator] table by `estimate --tool`.",
        inputs
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        cfg.what
    );
    let text = machine_toml(cfg, &header)?;
    let back = crate::replay::parse_monitor_config(
        &text,
        &output.display().to_string(),
        Some(f64::from(cfg.config.sample_rate_hz)),
    )?;
    if back.config != cfg.config || back.alarms != cfg.alarms || back.front_end != cfg.front_end {
        bail!("internal: the machine file written does not read back the same (please report)");
    }
    write_file(output, text.as_bytes())?;
    eprintln!("wrote {}", output.display());
    Ok(())
}

/// Prints the report and writes it with its plot under `--report-dir`.
fn emit_report(common: &Common, step: &str, report: &str, panels: &[FitPanel]) -> Result<()> {
    print!("{report}");
    if let Some(dir) = &common.report_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let svg = render_fits(&format!("calibrate {step}"), panels)?;
        write_file(&dir.join(format!("{step}.svg")), svg.as_bytes())?;
        write_file(&dir.join(format!("{step}.md")), report.as_bytes())?;
        eprintln!("wrote {}/{step}.md and {step}.svg", dir.display());
    }
    Ok(())
}

/// `v ± h` with a sensible number of digits.
fn pm(v: f64, h: f64) -> String {
    if h.is_finite() {
        format!("{v:.5} ± {h:.2e}")
    } else {
        format!("{v:.5} (no interval: as many points as parameters)")
    }
}

fn run_friction(common: &Common, traces: &[PathBuf]) -> Result<()> {
    let mut cfg = load_base(common.config.as_deref())?;
    let Input::Motor { feed, .. } = &mut cfg.config.input else {
        bail!(
            "{}: feed friction needs a motor input, not a dynamometer",
            cfg.what
        );
    };
    let axes = if feed.two_axis { 2 } else { 1 };
    let points = friction::air_points(traces, axes, &friction::Steady::default())?;
    let mut report = String::from("# Feed friction (calibrate friction)\n\n");
    let mut panels = Vec::new();
    for axis in 0..axes {
        let name = ["X", "Y"][axis];
        if axis == 1 && points[1].is_empty() {
            bail!("the drive has two axes but no trace carries feed_y_a / feed_vy_mm_min");
        }
        let f = friction::fit_axis(axis, &feed.axes[axis], &points[axis])?;
        let _ = writeln!(
            report,
            "## Axis {name}\n\n| file | from [s] | to [s] | v [mm/min] | i [A] | sd [A] | fit [A] | residual [A] |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
        );
        for (p, r) in f.points.iter().zip(&f.fit.residuals) {
            let _ = writeln!(
                report,
                "| {} | {:.2} | {:.2} | {:.1} | {:.5} | {:.5} | {:.5} | {:+.2e} |",
                p.file.display(),
                p.from_s,
                p.to_s,
                p.velocity_mm_min,
                p.current_a,
                p.current_sd_a,
                p.current_a - r,
                r
            );
        }
        let a = &f.axis_out;
        let _ = writeln!(
            report,
            "\ncurrent_offset_a = {}\ncoulomb_n = {}\nviscous_n_per_mm_min = {}\n(95 % intervals; k_f = {:.1} N/A from the machine file; residual rms {:.2e} A, {} dof)\n",
            pm(f64::from(a.current_offset_a), f.ci95[0]),
            pm(f64::from(a.coulomb_n), f.ci95[1]),
            pm(f64::from(a.viscous_n_per_mm_min), f.ci95[2]),
            a.force_per_amp_n_per_a(),
            f.fit.rms,
            f.fit.dof
        );
        for n in &f.notes {
            let _ = writeln!(report, "Note: {n}\n");
        }
        let vmax = f
            .points
            .iter()
            .map(|p| p.velocity_mm_min.abs())
            .fold(0.0, f64::max);
        let curve = |sign: f64| -> Vec<(f64, f64)> {
            (0..=20)
                .map(|k| {
                    let v = sign * vmax * k.max(1) as f64 / 20.0;
                    (v, f.fit.coef[0] + f.fit.coef[1] * sign + f.fit.coef[2] * v)
                })
                .collect()
        };
        panels.push(FitPanel {
            title: format!("axis {name}: idle current"),
            labels: ("v [mm/min]".into(), "i [A]".into()),
            points: f
                .points
                .iter()
                .map(|p| (p.velocity_mm_min, p.current_a))
                .collect(),
            curves: vec![curve(-1.0), curve(1.0)],
            log: false,
        });
        feed.axes[axis] = f.axis_out;
    }
    emit_report(common, "friction", &report, &panels)?;
    write_machine(&common.output, &cfg, "calibrate friction", traces)
}

fn run_spindle(common: &Common, breaks: Option<&[f64]>, traces: &[PathBuf]) -> Result<()> {
    let mut cfg = load_base(common.config.as_deref())?;
    if let Some(b) = breaks {
        if b.iter().any(|v| !(v.is_finite() && *v > 0.0)) || b.windows(2).any(|w| w[1] <= w[0]) {
            bail!("--breaks: speeds must be positive and increasing (got {b:?})");
        }
    }
    let Input::Motor { spindle, .. } = &cfg.config.input else {
        bail!(
            "{}: spindle idle needs a motor input, not a dynamometer",
            cfg.what
        );
    };
    let points = spindle::speed_points(traces, &cfg.config, 0.005, 0.3)?;
    let fit = spindle::fit_idle(points, breaks, spindle)?;
    let unit = match spindle {
        estimator_core::drive::SpindleModel::Current { .. } => "A",
        estimator_core::drive::SpindleModel::Load { .. } => "%",
    };
    let mut report = format!(
        "# Spindle idle (calibrate spindle)\n\n| file | from [s] | to [s] | rpm | idle [{unit}] | se [{unit}] |\n| --- | --- | --- | --- | --- | --- |\n"
    );
    for p in &fit.points {
        let _ = writeln!(
            report,
            "| {} | {:.2} | {:.2} | {:.1} | {:.5} | {:.1e} |",
            p.file.display(),
            p.from_s,
            p.to_s,
            p.rpm,
            p.signal,
            p.signal_se
        );
    }
    let _ = writeln!(
        report,
        "\nLines ({} breaks), idle = intercept + slope * rpm:\n\n| from rpm | intercept [{unit}] | slope [{unit}/rpm] | points | residual rms |\n| --- | --- | --- | --- | --- |",
        if fit.auto_breaks { "chosen" } else { "given" }
    );
    let mut curves = Vec::new();
    let rpm_max = fit.points.iter().map(|p| p.rpm).fold(0.0, f64::max);
    for (k, p) in fit.pieces.iter().enumerate() {
        let _ = writeln!(
            report,
            "| {:.0} | {} | {} | {} | {:.2e} |",
            p.from_rpm,
            pm(p.fit.coef[0], p.fit.ci95[0]),
            pm(p.fit.coef[1], p.fit.ci95[1]),
            p.points,
            p.fit.rms
        );
        let to = fit.pieces.get(k + 1).map_or(rpm_max, |n| n.from_rpm);
        let from = if k == 0 {
            fit.points.first().map_or(0.0, |q| q.rpm)
        } else {
            p.from_rpm
        };
        curves.push(
            [from, to]
                .iter()
                .map(|&r| (r, p.fit.coef[0] + p.fit.coef[1] * r))
                .collect(),
        );
    }
    report.push('\n');
    let panels = [FitPanel {
        title: "spindle idle signal".into(),
        labels: ("rpm".into(), format!("idle [{unit}]")),
        points: fit.points.iter().map(|p| (p.rpm, p.signal)).collect(),
        curves,
        log: false,
    }];
    if let Input::Motor { spindle, .. } = &mut cfg.config.input {
        *spindle = fit.model;
    }
    emit_report(common, "spindle", &report, &panels)?;
    write_machine(&common.output, &cfg, "calibrate spindle", traces)
}

/// `<output stem>.<suffix>` beside the output.
fn beside(output: &Path, suffix: &str) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(|| "machine".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}.{suffix}"))
}

fn run_cutting(
    common: &Common,
    plan: &Path,
    poly_output: Option<&Path>,
    linear_output: Option<&Path>,
) -> Result<()> {
    let mut cfg = load_base(common.config.as_deref())?;
    let tool = cfg.config.estimator.tool;
    let cuts = cutting::read_cuts(plan, &cfg.config)?;
    let power = cutting::fit_power(&tool, &cuts, &cfg.config.estimator.coeffs)?;
    let linear = cutting::fit_linear_model(&tool, &cuts);
    let mut report = String::from(
        "# Cutting coefficients (calibrate cutting)\n\n| cut | mode | R_r | R_a | t_c [mm] | teeth (left out) | F_ax [N] | F_at or F_ay [N] | t_a [mm] | K_s [N/mm^2] | r1 |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for (c, i) in cuts.iter().zip(&power.inverted) {
        let (second, which) = match c.second {
            cutting::Second::Tangential(f) => (f, "F_at"),
            cutting::Second::Normal(f) => (f, "F_ay"),
        };
        let _ = writeln!(
            report,
            "| {} | {} | {:.3} | {:.3} | {:.4} | {} ({}) | {:.1} | {which} {:.1} | {:.4} | {:.1} | {:.4} |",
            c.source,
            match c.mode {
                MillingMode::Down => "down",
                MillingMode::Up => "up",
            },
            c.rr,
            c.ra,
            c.tc_mm,
            c.teeth,
            c.left_out,
            c.fx_n,
            second,
            i.t_a_mm,
            i.ks,
            i.r1
        );
    }
    let law_line = |name: &str, f: &cutting::LawFit| {
        let (lo, hi) = f.k_ci95();
        format!(
            "| {name} | {} | {:.4}..{:.4} | {} | {:.2} % |\n",
            f.law.k,
            lo,
            hi,
            pm(f.fit.coef[1], f.fit.ci95[1]),
            100.0 * f.fit.rms
        )
    };
    let _ = write!(
        report,
        "\nPower laws (eq. 9), fitted in logs: y = k t_a^p\n\n| law | k | k 95 % | p | residual rms |\n| --- | --- | --- | --- | --- |\n{}{}",
        law_line("K_s", &power.ks),
        law_line("r1", &power.r1)
    );
    match &power.r2 {
        Some(f) => report.push_str(&law_line("r2", f)),
        None => {
            let _ = writeln!(
                report,
                "| r2 | {} (kept) | | {} | no axial force measured |",
                power.coeffs.r2.k, power.coeffs.r2.p
            );
        }
    }
    let _ = writeln!(
        report,
        "\ntc_fit_mm = [{}, {}]\n",
        power.coeffs.tc_fit_mm.0, power.coeffs.tc_fit_mm.1
    );
    let mut panels = Vec::new();
    let ta: Vec<f64> = power.inverted.iter().map(|i| i.t_a_mm).collect();
    let (ta_lo, ta_hi) = ta
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
    let law_curve = |law: PowerLaw| -> Vec<(f64, f64)> {
        (0..=20)
            .map(|k| {
                let t = ta_lo * (ta_hi / ta_lo).powf(k as f64 / 20.0);
                (t, f64::from(law.k) * t.powf(f64::from(law.p)))
            })
            .collect()
    };
    for (name, law, vals) in [
        (
            "K_s [N/mm^2]",
            power.coeffs.ks,
            power.inverted.iter().map(|i| i.ks).collect::<Vec<_>>(),
        ),
        (
            "r1",
            power.coeffs.r1,
            power.inverted.iter().map(|i| i.r1).collect(),
        ),
    ] {
        panels.push(FitPanel {
            title: format!("{name} against t_a"),
            labels: ("t_a [mm]".into(), name.into()),
            points: ta.iter().copied().zip(vals).collect(),
            curves: vec![law_curve(law)],
            log: true,
        });
    }
    match &linear {
        Ok(l) => {
            let names = ["K_tc", "K_te", "K_rc", "K_re", "K_ac", "K_ae"];
            let _ = writeln!(
                report,
                "Linear shearing + edge model (paper 003 eq. 2, paper 004), relative residual rms {:.2} %:\n",
                100.0 * l.fit.rms
            );
            for (j, n) in names.iter().enumerate().take(l.fit.coef.len()) {
                let _ = writeln!(report, "- {n} = {}", pm(l.fit.coef[j], l.fit.ci95[j]));
            }
            if !l.axial {
                report.push_str("- K_ac, K_ae: not identified (no axial force), written as 0\n");
            }
            report.push('\n');
        }
        Err(e) => {
            let _ = writeln!(report, "Linear model not fitted: {e:#}\n");
        }
    }
    // The polynomial for the new coefficients, for the estimator's fast path.
    let poly_path =
        poly_output.map_or_else(|| beside(&common.output, "fxt_poly.rs"), Path::to_path_buf);
    let command = format!("host-sim calibrate cutting --plan {}", plan.display());
    match gen_poly::generate(&power.coeffs, &command) {
        Ok((text, fits)) => {
            write_file(&poly_path, text.as_bytes())?;
            let _ = writeln!(
                report,
                "f_xt polynomial written to {} ({}); build the firmware with \
                 ESTIMATOR_FXT_POLY={} to use it.\n",
                poly_path.display(),
                fits.iter()
                    .map(|f| format!(
                        "{}: p95 {:.3} %, max {:.3} %",
                        f.spec.name,
                        100.0 * f.quality.p95,
                        100.0 * f.quality.max
                    ))
                    .collect::<Vec<_>>()
                    .join("; "),
                poly_path.display()
            );
        }
        Err(e) => {
            let _ = writeln!(
                report,
                "No f_xt polynomial for these coefficients ({e:#}); the estimator uses the exact \
                 inversion.\n"
            );
        }
    }
    if let Ok(l) = &linear {
        let path =
            linear_output.map_or_else(|| beside(&common.output, "linear.toml"), Path::to_path_buf);
        let k = &l.coeffs;
        let text = format!(
            "# Linear shearing + edge coefficients from `{command}`:\n# paste into a scenario or voxel file.\n[material.linear]\nktc = {}\nkte = {}\nkrc = {}\nkre = {}\nkac = {}\nkae = {}\n",
            k.ktc, k.kte, k.krc, k.kre, k.kac, k.kae
        );
        write_file(&path, text.as_bytes())?;
        let _ = writeln!(
            report,
            "Linear coefficients written to {}.\n",
            path.display()
        );
    }
    cfg.config.estimator.coeffs = power.coeffs;
    // The fit's own error becomes the estimator's gain uncertainty (each estimate's sigma
    // then carries the calibration's share, method.md section 2).
    let gain = cutting::relative_force_rms(&tool, &cuts, &power.coeffs);
    if gain.is_finite() && gain < 0.5 {
        cfg.config.estimator.gain_uncertainty = gain as f32;
        let _ = writeln!(
            report,
            "Mean forces against eq. 7 with the fitted laws: {:.2} % rms (of F_at), written as \
             estimator.gain_uncertainty.\n",
            100.0 * gain
        );
    } else {
        let _ = writeln!(
            report,
            "Mean forces against eq. 7 with the fitted laws: {:.1} % rms: the power laws do not \
             describe these cuts (check the plan's depths and modes); gain_uncertainty kept.\n",
            100.0 * gain
        );
    }
    emit_report(common, "cutting", &report, &panels)?;
    write_machine(
        &common.output,
        &cfg,
        "calibrate cutting",
        &[plan.to_path_buf()],
    )
    .map_err(|e| anyhow!("{e:#}"))
}
