//! `teach`: records a good cut's force envelope (teach-in) into the machine file.
//!
//! The job is run once on a good tool and recorded: a raw trace, replayed here through the
//! machine file's Pipeline, or the board's own per-tooth records (`decode-telemetry`, or a
//! `replay` records CSV). The core's `EnvelopeRecorder` bins the revolution-mean force
//! against revolutions since the cut began (from where it first reaches a quarter of its
//! peak); the envelope goes into `[alarms.teach]`, where the alarms compare every later run
//! of the job with it (`alarms.teach.tolerance_rel` beyond the band, over
//! `alarms.teach.debounce_teeth` teeth).

use crate::calibrate::{load_base, write_machine};
use crate::records::RecordReader;
use crate::replay;
use crate::trace::TraceReader;
use anyhow::{bail, Context, Result};
use estimator_core::alarm::{EnvelopeRecorder, ENVELOPE_BINS};
use std::path::PathBuf;

/// Arguments of `host-sim teach`.
#[derive(clap::Args, Debug, Clone)]
pub struct TeachArgs {
    /// Machine file to start from (docs/formats.md); default: the built-in defaults.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Machine file to write: the input one with the taught envelope in [alarms.teach].
    #[arg(long, value_name = "FILE")]
    pub output: PathBuf,
    /// Raw trace of the good run (replayed with --config).
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with = "records",
        required_unless_present = "records"
    )]
    pub trace: Option<PathBuf>,
    /// Or the per-tooth records of the good run (records CSV of `decode-telemetry` or
    /// `replay`).
    #[arg(long, value_name = "FILE")]
    pub records: Option<PathBuf>,
    /// Revolutions per envelope bin; the envelope holds 128 bins, so the job may last
    /// 128 times this many revolutions.
    #[arg(long, default_value_t = 2, value_name = "REVS")]
    pub revs_per_bin: u16,
}

/// Runs `teach`.
pub fn run(args: &TeachArgs) -> Result<()> {
    if args.revs_per_bin == 0 {
        bail!("--revs-per-bin: at least 1");
    }
    let mut cfg = load_base(args.config.as_deref())?;
    let flutes = cfg.config.estimator.tool.flutes;
    let mut rec = EnvelopeRecorder::new(flutes, args.revs_per_bin);
    let mut teeth = 0u64;
    let input = match (&args.trace, &args.records) {
        (Some(path), _) => {
            let mut reader = TraceReader::open(path)?;
            let mut c = cfg.config.clone();
            if let Some(rate) = reader.detect_sample_rate_hz()? {
                c.sample_rate_hz = rate as f32;
            }
            replay::replay(&mut reader, &c, |r, _| {
                rec.push(r);
                teeth += 1;
            })
            .with_context(|| path.display().to_string())?;
            path.clone()
        }
        (None, Some(path)) => {
            let name = path.display().to_string();
            let f = std::fs::File::open(path).with_context(|| format!("cannot read {name}"))?;
            let mut reader = RecordReader::new(std::io::BufReader::new(f), &name)?;
            while let Some(row) = reader.next_row()? {
                rec.push(&row.record);
                teeth += 1;
            }
            path.clone()
        }
        (None, None) => bail!("give --trace or --records"),
    };
    let env = rec.finish();
    let name = input.display();
    if env.len == 0 || env.start_n <= 0.0 {
        bail!("{name}: no cutting in {teeth} tooth periods: nothing to teach");
    }
    let revs = teeth / u64::from(flutes.max(1));
    if revs > u64::from(args.revs_per_bin) * ENVELOPE_BINS as u64 + 10 {
        eprintln!(
            "warning: {name} is {revs} revolutions long; the envelope covers the first {} \
             (raise --revs-per-bin)",
            u64::from(args.revs_per_bin) * ENVELOPE_BINS as u64
        );
    }
    let peak = env
        .hi_n
        .iter()
        .take(env.len as usize)
        .fold(0.0f32, |a, &b| a.max(b));
    println!(
        "taught from {name}: {teeth} tooth periods, {} bins of {} revolutions from where the \
         force reached {:.1} N (a quarter of its {:.1} N peak); tolerance {:.0} % beyond the \
         band, {} teeth",
        env.len,
        env.revs_per_bin,
        env.start_n,
        peak,
        100.0 * cfg.alarms.teach.tolerance_rel,
        cfg.alarms.teach.debounce_teeth
    );
    cfg.alarms.teach.envelope = Some(env);
    write_machine(&args.output, &cfg, "teach", &[input])
}
