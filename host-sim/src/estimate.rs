//! `estimate`: runs the core's estimator over a CSV of per-tooth average forces.
//!
//! One row in, one row out, streamed (a record at a time), in input order, input columns
//! kept verbatim and the estimate appended. Only the file's structure is an error (a
//! missing column, a row with the wrong number of fields, text where a number belongs):
//! values the estimator cannot use (NaN, inf, `t_c <= 0`, forces below the floor) are its
//! business, and come back as a row with a status that says so. Nothing is dropped.
//!
//! Route by columns: `ft_n` means the motor route (`f_xt = F_ax / F_at`), `fy_n` the
//! dynamometer route (`f_x = F_ax / |(F_ax, F_ay)|`); with both present the caller must
//! choose.

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::{Estimate, Estimator, Measured};
use std::io::{Read, Write};

/// Column of the feed per tooth [mm/tooth].
pub const TC: &str = "tc_mm";
/// Column of the feed-direction force `F_ax`, N.
pub const FX: &str = "fx_n";
/// Column of the tangential force `F_at`, N (motor route).
pub const FT: &str = "ft_n";
/// Column of the force normal to the feed `F_ay`, N (dynamometer route).
pub const FY: &str = "fy_n";
/// Columns appended to every row, in order.
/// `dr_sigma_mm`, `da_sigma_mm`: 1-sigma from the tool file's `estimator.gain_uncertainty`
/// (a per-row force scatter is not known here; replay reports it from the filter).
pub const OUTPUT_COLUMNS: [&str; 8] = [
    "rr",
    "ra",
    "dr_mm",
    "da_mm",
    "status",
    "method",
    "dr_sigma_mm",
    "da_sigma_mm",
];

/// Which measured pair to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Route {
    /// From the columns present; an error if both `ft_n` and `fy_n` are.
    #[default]
    Auto,
    /// `fx_n`, `ft_n`.
    Motor,
    /// `fx_n`, `fy_n`.
    Dynamometer,
}

/// Where the inputs sit in a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Layout {
    tc: usize,
    fx: usize,
    /// `ft_n` or `fy_n`.
    other: usize,
    motor: bool,
}

/// What a run did, for the summary line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// Data rows read and written.
    pub rows: u64,
    /// Rows whose estimate is valid.
    pub valid: u64,
}

/// Finds the input columns in the header (names compared after trimming spaces).
fn layout(header: &csv::StringRecord, route: Route, file: &str) -> Result<Layout> {
    let find = |name: &str| header.iter().position(|h| h.trim() == name);
    for out in OUTPUT_COLUMNS {
        if find(out).is_some() {
            bail!(
                "{file}: input already has a column `{out}`, which the output adds; \
                 rename or remove it"
            );
        }
    }
    let need = |name: &str, why: &str| {
        find(name).ok_or_else(|| anyhow!("{file}: missing column `{name}` ({why})"))
    };
    let tc = need(TC, "feed per tooth, mm/tooth")?;
    let fx = need(FX, "feed-direction force, N")?;
    let motor = match (route, find(FT), find(FY)) {
        (Route::Motor, ..) | (Route::Auto, Some(_), None) => true,
        (Route::Dynamometer, ..) | (Route::Auto, None, Some(_)) => false,
        (Route::Auto, Some(_), Some(_)) => bail!(
            "{file}: both `{FT}` and `{FY}` present; choose the route with \
             --route motor or --route dynamometer"
        ),
        (Route::Auto, None, None) => bail!(
            "{file}: missing column `{FT}` (motor route: tangential force, N) or \
             `{FY}` (dynamometer route: force normal to the feed, N)"
        ),
    };
    let other = if motor {
        need(FT, "tangential force, N; motor route")?
    } else {
        need(FY, "force normal to the feed, N; dynamometer route")?
    };
    Ok(Layout {
        tc,
        fx,
        other,
        motor,
    })
}

/// One number from a field. NaN and inf parse (the estimator flags them); empty or
/// non-numeric text does not.
fn number(record: &csv::StringRecord, idx: usize, col: &str, file: &str) -> Result<f32> {
    let line = record.position().map_or(0, |p| p.line());
    let raw = record.get(idx).unwrap_or("");
    let text = raw.trim();
    if text.is_empty() {
        bail!("{file} line {line}, column `{col}`: empty value (write NaN for a missing one)");
    }
    text.parse::<f32>()
        .map_err(|_| anyhow!("{file} line {line}, column `{col}`: `{raw}` is not a number"))
}

/// The measured forces of one row.
fn measured(rec: &csv::StringRecord, lay: &Layout, file: &str) -> Result<(f32, Measured)> {
    let tc = number(rec, lay.tc, TC, file)?;
    let fx_n = number(rec, lay.fx, FX, file)?;
    let m = if lay.motor {
        Measured::Motor {
            fx_n,
            ft_n: number(rec, lay.other, FT, file)?,
        }
    } else {
        Measured::Dynamometer {
            fx_n,
            fy_n: number(rec, lay.other, FY, file)?,
        }
    };
    Ok((tc, m))
}

/// The appended fields of one estimate, in [`OUTPUT_COLUMNS`] order.
fn fields(e: &Estimate, radius_mm: f32) -> [String; 8] {
    [
        e.rr.to_string(),
        e.ra.to_string(),
        e.dr_mm.to_string(),
        e.da_mm.to_string(),
        e.status.to_string(),
        e.method.name().to_string(),
        (e.rr_sigma * radius_mm).to_string(),
        (e.ra_sigma * radius_mm).to_string(),
    ]
}

/// Streams `input` (CSV with a header) through `est` into `output`. `file` names the
/// input in error messages.
pub fn run(
    input: impl Read,
    file: &str,
    output: impl Write,
    est: &Estimator,
    route: Route,
) -> Result<Summary> {
    // flexible: a short or long row is reported by us, with the line and the counts.
    let mut rd = csv::ReaderBuilder::new()
        .flexible(true)
        .has_headers(true)
        .from_reader(input);
    let mut wr = csv::Writer::from_writer(output);
    let header = rd
        .headers()
        .with_context(|| format!("{file}: cannot read the header"))?
        .clone();
    if header.iter().all(|h| h.trim().is_empty()) {
        bail!("{file}: empty file or empty header line (line 1 must name the columns)");
    }
    let lay = layout(&header, route, file)?;
    let mut out_header = header.clone();
    out_header.extend(OUTPUT_COLUMNS);
    wr.write_record(&out_header)
        .context("writing the output header")?;
    let mut summary = Summary::default();
    let mut rec = csv::StringRecord::new();
    while rd
        .read_record(&mut rec)
        .with_context(|| format!("{file}: cannot read"))?
    {
        if rec.len() != header.len() {
            let line = rec.position().map_or(0, |p| p.line());
            bail!(
                "{file} line {line}: {} fields, the header has {}",
                rec.len(),
                header.len()
            );
        }
        let (tc, m) = measured(&rec, &lay, file)?;
        let e = est.estimate(tc, m);
        summary.rows += 1;
        summary.valid += u64::from(e.status.is_valid());
        let mut row = rec.clone();
        row.extend(fields(&e, est.config().tool.radius_mm));
        wr.write_record(&row).context("writing the output")?;
    }
    wr.flush().context("writing the output")?;
    Ok(summary)
}
