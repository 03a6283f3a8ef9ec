//! host-sim: runs estimator-core on the desktop (see `host-sim --help`).

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use host_sim::{config, estimate, gen_poly, plot, replay, sim, trace, write_then_rename};
use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The committed polynomial file, found from this crate's source tree so that the command
/// works from any directory of the checkout.
fn fxt_poly_rs() -> PathBuf {
    let host_sim = Path::new(env!("CARGO_MANIFEST_DIR"));
    host_sim
        .parent()
        .unwrap_or(host_sim)
        .join("estimator-core/src/fxt_poly.rs")
}

const ESTIMATE_HELP: &str = "\
INPUT: CSV with a header line, one row per tooth period (per-tooth average forces).
Columns, in any order; other columns are copied to the output unchanged:
  tc_mm   feed per tooth [mm/tooth]
  fx_n    average force in the feed direction F_ax [N], signed as in method.md eq. 7:
          negative for light down-milling cuts (the cutter pulls the work), positive in a slot
and either (motor route, the product's)
  ft_n    average tangential force F_at [N] (spindle torque / tool radius)
or (dynamometer route)
  fy_n    average force normal to the feed F_ay [N]
NaN or inf values are not errors: the row comes out with status non_finite.

OUTPUT: the input columns, then
  rr, ra        radial and axial immersion ratios R_r = d_r/R, R_a = d_a/R
  dr_mm, da_mm  radial and axial depth of cut [mm]
  status        `valid`, or flags joined by `|`: not_cutting, rr_clamped, ra_clamped,
                tc_out_of_range, non_finite, ambiguous (trust a row only when valid)
  method        what produced rr: polynomial, table3, inversion, none
  dr_sigma_mm, da_sigma_mm
                1-sigma of the depths from the tool file's estimator.gain_uncertainty
                (the calibration's gain error; 0 by default)

DEFAULTS (each can be changed in the --tool file): tool radius 8 mm, 4 flutes, helix 30 deg,
down milling, the paper's Table 2 cutting coefficients, force floor 2 N, solver auto.
Tool file example (TOML; every key optional, unknown keys are errors):
";

/// The help text after the options: columns, units, signs, defaults, a tool file.
fn estimate_help() -> String {
    let example: String = config::TOOL_FILE_EXAMPLE
        .lines()
        .map(|l| format!("  {l}\n"))
        .collect();
    format!("{ESTIMATE_HELP}{}", example.trim_end())
}

/// Desktop tools around the sensorless tool monitor's estimator.
#[derive(Parser, Debug)]
#[command(name = "host-sim", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate a built-in cut with a flute breaking, replay it, print true vs estimated
    /// depths of cut and the alarm, write a plot and the CSVs (start here).
    #[command(after_help = host_sim::demo::DEMO_HELP)]
    Demo(host_sim::demo::DemoArgs),
    /// Identify the machine's constants: feed friction, spindle idle, cutting coefficients.
    #[command(subcommand)]
    Calibrate(host_sim::calibrate::CalibrateCmd),
    /// Write a machine file as Rust source for the firmware build
    /// (FIRMWARE_MACHINE_RS=<output> cargo build -p firmware ...).
    MachineRs {
        /// Machine file (replay's --config, what `calibrate` writes).
        #[arg(long, value_name = "FILE")]
        config: PathBuf,
        /// Rust source to write.
        #[arg(long, value_name = "FILE")]
        output: PathBuf,
    },
    /// Teach-in: record a good run's force envelope into the machine file.
    Teach(host_sim::teach::TeachArgs),
    /// Decode a capture of the board's UART telemetry into the per-tooth records CSV.
    #[command(after_help = host_sim::telemetry::DECODE_HELP)]
    DecodeTelemetry(host_sim::telemetry::DecodeArgs),
    /// Fit the f_xt polynomials from the forward model and write them as Rust constants.
    GenPoly {
        /// Cutting coefficients (TOML: ks = {k, p}, r1, r2, tc_fit_mm = [lo, hi]);
        /// default: the paper's Table 2.
        #[arg(long, value_name = "FILE")]
        coeffs: Option<PathBuf>,
        /// Where to write; default: estimator-core/src/fxt_poly.rs of this checkout.
        #[arg(long, value_name = "FILE")]
        output: Option<PathBuf>,
        /// Compare with the file instead of writing it; fail if it is stale.
        #[arg(long)]
        check: bool,
    },
    /// Estimate radial and axial depth of cut from per-tooth average forces (CSV).
    #[command(after_help = estimate_help())]
    Estimate {
        /// Per-tooth CSV (see below).
        #[arg(long, value_name = "FILE")]
        input: PathBuf,
        /// Tool and cutting settings (TOML) overriding the defaults below; a machine file
        /// (replay's --config, what `calibrate` writes) works too: its [estimator] table.
        #[arg(long, value_name = "FILE")]
        tool: Option<PathBuf>,
        /// Output CSV; default: standard output.
        #[arg(long, value_name = "FILE")]
        output: Option<PathBuf>,
        /// How to solve for R_r; default: the tool file's, else auto (polynomial for the
        /// motor route where it applies, exact inversion otherwise).
        #[arg(long, value_enum)]
        solver: Option<SolverArg>,
        /// Which force pair to use; auto picks from the columns present.
        #[arg(long, value_enum, default_value_t = RouteArg::Auto)]
        route: RouteArg,
    },
    /// Simulate a cut (tool, machine, timeline in a scenario TOML) into a raw trace CSV.
    #[command(
        after_help = "Scenario format: host-sim/examples/cut.toml (every key commented) and \
                      the `host_sim::sim::Scenario` docs. Trace format: docs/formats.md."
    )]
    Simulate {
        /// Scenario (TOML).
        #[arg(long, value_name = "FILE")]
        scenario: PathBuf,
        /// Raw trace CSV to write; default: standard output.
        #[arg(long, value_name = "FILE")]
        output: Option<PathBuf>,
    },
    /// Replay a raw trace (or a Kistler DynoWare export) through the streaming Monitor.
    #[command(after_help = replay::REPLAY_HELP)]
    Replay(replay::ReplayArgs),
    /// Convert a raw trace CSV into the binary samples of the QEMU image (docs/formats.md).
    TraceBin {
        /// Raw trace CSV.
        #[arg(long, value_name = "FILE")]
        trace: PathBuf,
        /// Binary sample file to write.
        #[arg(long, value_name = "FILE")]
        output: PathBuf,
    },
    /// Time replay (parse + Monitor, and Monitor alone) on a synthetic 3-channel 20 kS/s
    /// trace written to a temporary file (BENCHMARKS.md, "Replay throughput").
    BenchReplay {
        /// Length of the synthetic trace [s].
        #[arg(long, default_value_t = 60.0)]
        seconds: f64,
        /// Runs of each measurement; the fastest is reported.
        #[arg(long, default_value_t = 3)]
        repeat: u32,
    },
    /// Simulate milling a block along a toolpath (G-code or timed CSV) by voxel material
    /// removal (paper 004): forces, torque and the true engagement per 1/24 revolution.
    Voxel(host_sim::voxel::VoxelArgs),
    /// Measure the alarms on many simulated cuts: detection rate and latency of flute
    /// breakage, chipping, tool loss, overload, teach-in excursions and wear, and false
    /// alarms per hour of cutting.
    #[command(
        after_help = "Each case: random tool (2-4 flutes, R 4-8 mm), speed 1200-4000 \
                      rpm, feed 0.04-0.2 mm/tooth, R_r 0.2-1.6, R_a 0.3-1.5, down or up \
                      milling, runout up to 35 % of the chip on one flute, 3 % noise on the \
                      tooth averages, current-loop lag, entry and exit through faces of the work, feed and speed \
                      changes. Sets: normal (no damage), break, chip (30-70 % of the edge), \
                      gone (whole tool) (damage in the flute's cut, where it is loaded), overload, taught (teach-in on, the taught job \
                      again), teach (the job on 40 % deeper stock), wear (forces rising by \
                      half against a known engagement). See host_sim::evaluate."
    )]
    EvaluateAlarms {
        /// `small` (CI) or `full` (BENCHMARKS.md).
        #[arg(long, default_value = "small")]
        set: SetArg,
        /// Seed of the draws (the first, with `--seeds`). Seeds below 8192 draw as the first
        /// evaluations did, so the cases named in tests reproduce, and seeds that differ only
        /// in bits 8-14 share their draws (tool, cut and damage; other noise); from 8192 on
        /// every case is its own.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Run the set at this many consecutive seeds from `--seed` and report them pooled
        /// (a held-out block: `--seed 8193 --seeds 96`), with every false alarm and every
        /// full breakage missed or later than a revolution named by seed, set and index
        /// (with how far it stood above the noise by the deadline: the separation in sigma
        /// of the best detector told in advance how the forces would change, on every
        /// sample and on the tooth periods' sums; and how far from the nearest normal cut,
        /// the same cut leaving the work through a face wherever it lies, the exits the
        /// alarms must not take for a break: a break far from every exit is one a better
        /// rule could catch, one near an exit none can without false alarms).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100_000))]
        seeds: u64,
        /// Worker threads.
        #[arg(long, default_value_t = 2)]
        threads: usize,
        /// Exit with an error on a false alarm in any set, a missed overload or teach-in
        /// excursion, fewer than 90 % of wear warnings, fewer than 90 % of full breakages
        /// caught or fewer than 90 % within one revolution of the broken flute's first
        /// missed cut (CI's regression floor).
        #[arg(long)]
        check: bool,
        /// Also list every case's outcome (stderr).
        #[arg(long)]
        verbose: bool,
        /// Average every tooth from the encoder pulse (`align_window = false`), for
        /// comparison: by default the monitor learns where no flute cuts and begins the
        /// tooth windows there.
        #[arg(long)]
        window_at_pulse: bool,
        /// Run the monitor as calibrated with cuts down to this feed per tooth [mm]. The
        /// simulator's material follows Table 2's laws at every feed, so such a calibration
        /// finds the same laws and trusts them from this feed on. By default they are
        /// trusted from the paper's 0.1042 mm: the cuts drawn below it (from 0.04 mm) are
        /// estimated but flagged out of range, and the alarms take the worst engagement
        /// there.
        #[arg(long, value_name = "MM", allow_negative_numbers = true)]
        tc_fit_from: Option<f32>,
        /// The servo amplifiers' current-loop lag on every channel [s], a first-order time
        /// constant, instead of the cases' 0.0005 (the same draws otherwise); the monitor is
        /// told it too (`spindle_lag_s`, as a calibration measures it). `0` measures what the
        /// lag costs the alarms.
        #[arg(long, value_name = "S", allow_negative_numbers = true)]
        lag_s: Option<f64>,
        /// The spindle current loop's time constant the monitor is told [s]
        /// (`spindle_lag_s`), instead of the one the cases are drawn with: `0` leaves the lag
        /// unmodelled (the drop trip as before it allowed for the lag), a value off the
        /// cases' measures what a mis-set calibration costs.
        #[arg(long, value_name = "S", allow_negative_numbers = true)]
        monitor_lag_s: Option<f32>,
        /// Trace one case instead of running the sets: `KIND:INDEX` as the goal's list
        /// names it ("seed 10794 break 16" is `--seed 10794 --case break:16`). Prints the
        /// case, its cut at the damage (the true R_r, R_a and t_c), what came of it (for a
        /// damage, its separation by the deadline and from the nearest exit as in the
        /// goal's list), and its tooth
        /// records around the damage (or the first alarm):
        /// forces measured and true, flutes intact, estimate, the hand-over inside the
        /// period (`ho_z`, sigma), the drop trip armed for the next period, status and
        /// alarm.
        #[arg(long, value_name = "KIND:INDEX", conflicts_with_all = ["seeds", "check", "verbose"])]
        case: Option<String>,
        /// With `--case`: records from this time [s] (default: 3 revolutions before the
        /// damage or the first alarm, whichever came first).
        #[arg(long, value_name = "S", requires = "case")]
        from: Option<f64>,
        /// With `--case`: records up to this time [s] (default: a revolution past the first
        /// alarm, or 4 past the damage where none came).
        #[arg(long, value_name = "S", requires = "case")]
        to: Option<f64>,
    },
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum SetArg {
    Small,
    Full,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum SolverArg {
    Auto,
    Polynomial,
    Table3,
    Inversion,
}

impl From<SolverArg> for estimator_core::Solver {
    fn from(s: SolverArg) -> Self {
        use estimator_core::Solver;
        match s {
            SolverArg::Auto => Solver::Auto,
            SolverArg::Polynomial => Solver::Polynomial,
            SolverArg::Table3 => Solver::Table3,
            SolverArg::Inversion => Solver::Inversion,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum RouteArg {
    Auto,
    Motor,
    Dynamometer,
}

impl From<RouteArg> for estimate::Route {
    fn from(r: RouteArg) -> Self {
        match r {
            RouteArg::Auto => estimate::Route::Auto,
            RouteArg::Motor => estimate::Route::Motor,
            RouteArg::Dynamometer => estimate::Route::Dynamometer,
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // `{:#}` puts the whole context chain on one line.
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::GenPoly {
            coeffs,
            output,
            check,
        } => gen_poly_cmd(coeffs.as_deref(), output.as_deref(), check),
        Command::Estimate {
            input,
            tool,
            output,
            solver,
            route,
        } => estimate_cmd(&input, tool.as_deref(), output.as_deref(), solver, route),
        Command::Simulate { scenario, output } => simulate_cmd(&scenario, output.as_deref()),
        Command::Replay(args) => replay_cmd(&args),
        Command::TraceBin { trace, output } => trace_bin_cmd(&trace, &output),
        Command::BenchReplay { seconds, repeat } => bench_replay_cmd(seconds, repeat),
        Command::Voxel(args) => host_sim::voxel::run(&args),
        Command::MachineRs { config, output } => machine_rs_cmd(&config, &output),
        Command::Teach(args) => host_sim::teach::run(&args),
        Command::Calibrate(cmd) => host_sim::calibrate::run(&cmd),
        Command::Demo(args) => host_sim::demo::run(&args).map(drop),
        Command::DecodeTelemetry(args) => host_sim::telemetry::run(&args).map(drop),
        Command::EvaluateAlarms {
            set,
            seed,
            seeds,
            threads,
            check,
            verbose,
            window_at_pulse,
            tc_fit_from,
            lag_s,
            monitor_lag_s,
            case,
            from,
            to,
        } => {
            let setup = host_sim::evaluate::Setup {
                align: !window_at_pulse,
                tc_fit_from_mm: tc_fit_from,
                lag_s,
                monitor_lag_s,
            };
            check_setup(setup)?;
            match case {
                Some(case) => trace_cmd(&case, seed, setup, (from, to)),
                None => evaluate_cmd(
                    set,
                    seed..seed.saturating_add(seeds),
                    threads,
                    check,
                    verbose,
                    setup,
                ),
            }
        }
    }
}

fn machine_rs_cmd(config: &Path, output: &Path) -> Result<()> {
    // Without sample_rate_hz in the file, the board's default rate.
    let rate = f64::from(estimator_core::MonitorConfig::default().sample_rate_hz);
    let m = replay::load_monitor_config(Some(config), Some(rate))?;
    let machine = estimator_core::MachineConfig {
        monitor: m.config,
        alarms: m.alarms,
        front_end: m.front_end,
    };
    machine
        .clone()
        .build()
        .map_err(|e| anyhow::anyhow!("{}: {e}", config.display()))?;
    let text = host_sim::machine_rs::render(&machine, &config.display().to_string())?;
    write_then_rename(output, |w| w.write_all(text.as_bytes()).map_err(Into::into))?;
    eprintln!("wrote {}", output.display());
    Ok(())
}

/// `--lag-s`'s bound [s]: far past any current loop's (a fraction of a millisecond). The
/// cases' tooth periods are 3.75-25 ms: a lag near them smears each tooth into the next
/// (the monitor's own bound, `MAX_SPINDLE_LAG_S`, is the same).
const MAX_LAG_S: f64 = 0.01;

fn check_setup(setup: host_sim::evaluate::Setup) -> Result<()> {
    let high_mm = estimator_core::TABLE2.tc_fit_mm.1;
    if let Some(lo) = setup
        .tc_fit_from_mm
        .filter(|lo| !(*lo > 0.0 && *lo <= high_mm))
    {
        bail!("--tc-fit-from {lo}: the feed the calibration reached must be above 0 and at most the fitted range's high end, {high_mm} mm");
    }
    if let Some(lag) = setup.lag_s.filter(|l| !(*l >= 0.0 && *l <= MAX_LAG_S)) {
        bail!("--lag-s {lag}: a current-loop time constant from 0 to {MAX_LAG_S} s");
    }
    let most = estimator_core::monitor::MAX_SPINDLE_LAG_S;
    if let Some(lag) = setup.monitor_lag_s.filter(|l| !(*l >= 0.0 && *l <= most)) {
        bail!("--monitor-lag-s {lag}: a current-loop time constant from 0 to {most} s");
    }
    Ok(())
}

/// `evaluate-alarms --case KIND:INDEX`: one case, traced.
fn trace_cmd(
    case: &str,
    seed: u64,
    setup: host_sim::evaluate::Setup,
    (from, to): (Option<f64>, Option<f64>),
) -> Result<()> {
    use host_sim::evaluate;
    for (name, v) in [("--from", from), ("--to", to)] {
        if let Some(v) = v.filter(|v| !v.is_finite()) {
            bail!("{name} {v}: a time in seconds");
        }
    }
    if let (Some(a), Some(b)) = (from, to) {
        if a > b {
            bail!("--from {a} is after --to {b}");
        }
    }
    let (kind, index) = evaluate::parse_case(case)?;
    let mut c = evaluate::draw_case(kind, index, seed)?;
    setup.apply(&mut c);
    let (outcome, records) = evaluate::trace_case(&c)?;
    let window = evaluate::trace_window(&outcome);
    let window = match (from, to, window) {
        (Some(a), Some(b), _) => (a, b),
        (a, b, Some((wa, wb))) => (a.unwrap_or(wa), b.unwrap_or(wb)),
        (a, b, None) => {
            if a.is_none() || b.is_none() {
                eprintln!(
                    "no damage and no alarm in this case: give --from and --to to see records"
                );
            }
            (a.unwrap_or(f64::INFINITY), b.unwrap_or(f64::NEG_INFINITY))
        }
    };
    let exit = evaluate::nearest_exit(&c, &outcome, &records)?;
    print!(
        "{}",
        evaluate::format_trace(&c, &outcome, &records, exit.as_ref(), window)
    );
    Ok(())
}

fn evaluate_cmd(
    set: SetArg,
    seeds: std::ops::Range<u64>,
    threads: usize,
    check: bool,
    verbose: bool,
    setup: host_sim::evaluate::Setup,
) -> Result<()> {
    use host_sim::evaluate;
    let sizes = match set {
        SetArg::Small => evaluate::SetSizes::SMALL,
        SetArg::Full => evaluate::SetSizes::FULL,
    };
    let start = std::time::Instant::now();
    let outcomes = evaluate::evaluate(sizes, seeds.clone(), threads, setup)?;
    let fig = evaluate::figures(&outcomes);
    if verbose {
        for o in &outcomes {
            eprintln!("{o:?}");
        }
    }
    println!("{}", evaluate::report(&fig));
    // (Each late or missed break run again, its nearest exit searched: seconds each.)
    let exceptions = evaluate::exceptions(&outcomes, |o| evaluate::nearest_exit_note(o, setup));
    if !exceptions.is_empty() {
        println!("Against the goal (false alarms; full breakages missed or late):\n\n{exceptions}");
    }
    let seed_text = match seeds.end - seeds.start {
        1 => format!("seed {}", seeds.start),
        _ => format!("seeds {}-{}", seeds.start, seeds.end - 1),
    };
    eprintln!(
        "{} cases in {:.1} s ({seed_text})",
        outcomes.len(),
        start.elapsed().as_secs_f64()
    );
    if check {
        evaluate::check_goals(&fig)?;
        eprintln!(
            "check passed: no false alarm, every overload and teach-in excursion, >= 90 % of \
             wear warnings, >= 90 % of breakages caught and >= 90 % within one revolution of the first missed cut"
        );
    }
    Ok(())
}

fn gen_poly_cmd(coeffs_file: Option<&Path>, output: Option<&Path>, check: bool) -> Result<()> {
    let coeffs = config::load_coeffs(coeffs_file)?;
    let command = match coeffs_file {
        None => gen_poly::COMMAND.to_string(),
        Some(p) => format!("{} --coeffs {}", gen_poly::COMMAND, p.display()),
    };
    let path = output.map_or_else(fxt_poly_rs, Path::to_path_buf);
    let path = path.as_path();
    let (text, fits) = gen_poly::generate(&coeffs, &command)?;
    for f in &fits {
        println!(
            "{}: p95 {:.3} %, max {:.3} % (at R_r {}, t_c {} mm)",
            f.spec.name,
            f.quality.p95 * 100.0,
            f.quality.max * 100.0,
            f.quality.worst_at.0,
            f.quality.worst_at.1
        );
    }
    if check {
        let on_disk = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        if let Some((line, want, have)) = gen_poly::first_difference(&text, &on_disk) {
            bail!(
                "{} is stale (line {line}: generated `{}`, file has `{}`); regenerate with `{command}`",
                path.display(),
                want.trim(),
                have.trim()
            );
        }
        println!("{} is up to date", path.display());
    } else {
        std::fs::write(path, &text).with_context(|| format!("cannot write {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn estimate_cmd(
    input: &Path,
    tool: Option<&Path>,
    output: Option<&Path>,
    solver: Option<SolverArg>,
    route: RouteArg,
) -> Result<()> {
    let mut cfg = config::load_estimator_config(tool)?;
    if let Some(s) = solver {
        cfg.solver = s.into();
    }
    let what = tool.map_or("default configuration".to_string(), |p| {
        p.display().to_string()
    });
    let est = cfg.build().map_err(|e| anyhow::anyhow!("{what}: {e}"))?;
    let file = input.display().to_string();
    let rd = File::open(input).with_context(|| format!("cannot open {file}"))?;
    let rd = BufReader::new(rd);
    let summary = match output {
        Some(p) => write_then_rename(p, |w| estimate::run(rd, &file, w, &est, route.into()))?,
        None => {
            let out = std::io::stdout().lock();
            let s = estimate::run(rd, &file, BufWriter::new(out), &est, route.into())?;
            std::io::stdout().flush().context("writing the output")?;
            s
        }
    };
    eprintln!(
        "{file}: {} rows, {} valid, {} flagged",
        summary.rows,
        summary.valid,
        summary.rows - summary.valid
    );
    Ok(())
}

fn simulate_cmd(scenario: &Path, output: Option<&Path>) -> Result<()> {
    let name = scenario.display().to_string();
    let text = std::fs::read_to_string(scenario).with_context(|| format!("cannot read {name}"))?;
    let sc = sim::Scenario::from_toml(&text, &name)?;
    let started = std::time::Instant::now();
    let summary = match output {
        Some(p) => write_then_rename(p, |w| Ok(sim::write_trace(&sc, w)?.0))?,
        None => {
            let out = BufWriter::new(std::io::stdout().lock());
            sim::write_trace(&sc, out)?.0
        }
    };
    let secs = started.elapsed().as_secs_f64();
    eprintln!(
        "{name}: {} rows, {:.3} s of trace in {secs:.2} s ({:.0}x real time); {} sync pulses \
         ({} dropped); clipped samples {:?}; peak F_t {:.1} N",
        summary.rows,
        summary.duration_s,
        summary.duration_s / secs.max(1e-9),
        summary.sync_pulses,
        summary.sync_dropped,
        summary.clipped,
        summary.peak_ft_n
    );
    Ok(())
}

fn replay_cmd(args: &replay::ReplayArgs) -> Result<()> {
    let plot_format = args
        .plot
        .as_deref()
        .map(plot::PlotFormat::from_path)
        .transpose()?;
    let (mut src, loaded) = replay::open_replay(args)?;
    let name = src.name().to_string();
    let format = if args.bits {
        replay::RecordFormat::Bits
    } else {
        replay::RecordFormat::Csv
    };
    let outputs = replay::ReplayOutputs {
        plot: plot_format.is_some(),
        alarms: loaded.alarms,
        events: args.alarms.is_some(),
    };
    let total = std::fs::metadata(&args.trace).ok().map(|m| m.len());
    let pb = replay::progress_bar(total);
    let (summary, plot_data, events) = match &args.output {
        Some(p) => write_then_rename(p, |w| {
            replay::replay_to(&mut *src, &loaded.config, w, format, &outputs, pb.as_ref())
        })?,
        None => {
            let out = BufWriter::new(std::io::stdout().lock());
            replay::replay_to(
                &mut *src,
                &loaded.config,
                out,
                format,
                &outputs,
                pb.as_ref(),
            )?
        }
    };
    eprint!("{}", summary.report(&name));
    if let Some(path) = &args.alarms {
        write_then_rename(path, |w| {
            w.write_all(events.as_bytes())
                .with_context(|| format!("cannot write {}", path.display()))
        })?;
        eprintln!("wrote {}", path.display());
    }
    if let (Some(path), Some(fmt), Some(data)) = (&args.plot, plot_format, plot_data) {
        let bytes = plot::render(&data, fmt)?;
        write_then_rename(path, |w| {
            w.write_all(&bytes)
                .with_context(|| format!("cannot write {}", path.display()))
        })?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn trace_bin_cmd(trace_path: &Path, output: &Path) -> Result<()> {
    let mut rd = trace::TraceReader::open(trace_path)?;
    let n = write_then_rename(output, |w| trace::write_sample_bin(&mut rd, w))?;
    eprintln!(
        "{}: {n} samples -> {}",
        trace_path.display(),
        output.display()
    );
    Ok(())
}

fn bench_replay_cmd(seconds: f64, repeat: u32) -> Result<()> {
    let r = replay::bench_replay(seconds, repeat, &std::env::temp_dir())?;
    println!(
        "replay of {:.1} s at 20 kS/s, 3 channels ({} samples, {:.1} MB, {} tooth records), \
         best of {repeat}:",
        r.seconds,
        r.samples,
        r.bytes as f64 / 1e6,
        r.records
    );
    println!(
        "  parse + Monitor: {:.3} s wall, {:.0}x real time ({:.2} M samples/s)",
        r.replay_s,
        r.replay_x(),
        r.samples as f64 / r.replay_s / 1e6
    );
    println!(
        "  Monitor only:    {:.3} s wall, {:.0}x real time ({:.1} M samples/s)",
        r.monitor_s,
        r.monitor_x(),
        r.samples as f64 / r.monitor_s / 1e6
    );
    Ok(())
}
