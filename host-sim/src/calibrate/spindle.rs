//! `calibrate spindle`: the idle signal of the spinning tool out of the cut (current [A] or
//! load [%]) against speed, as the piecewise lines the core evaluates
//! (`estimator_core::table::Segments`).
//!
//! The speed and the per-tooth mean signal come from the Monitor itself, run with the idle
//! line set to zero: its record's second force is then the force of the whole signal, and
//! the spindle model's own inverse (`SpindleModel::signal_for_force`) turns it back into
//! the signal. So the tooth synchronisation, the rpm and the load chain are the ones the
//! board runs, not a second implementation.
//!
//! Where a curve breaks (paper 003: a slope change at 11 000 rpm, a winding switch at
//! 3 568 rpm) the lines are fitted piecewise. The breaks are given, or chosen among the
//! gaps between the measured speeds by the Bayesian information criterion, which charges
//! each extra line for its parameters: a straight curve keeps one line.

use super::stats::{fit_linear, LinearFit};
use crate::replay;
use crate::trace::TraceReader;
use anyhow::{anyhow, bail, Context, Result};
use estimator_core::drive::SpindleModel;
use estimator_core::monitor::{FeedVelocity, Input};
use estimator_core::table::{Segment, Segments, SEGMENTS_CAPACITY};
use estimator_core::{MonitorConfig, Status};
use std::path::PathBuf;

/// Records that say nothing about the spindle signal.
const BAD: Status = Status(
    Status::PERIOD_INVALID.0 | Status::NO_SYNC.0 | Status::INPUT_FAULT.0 | Status::NON_FINITE.0,
);

/// The mean idle signal over one steady speed.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedPoint {
    /// Where it came from.
    pub file: PathBuf,
    /// Start of the part averaged [s].
    pub from_s: f64,
    /// End [s].
    pub to_s: f64,
    /// Mean speed [rpm].
    pub rpm: f64,
    /// Mean signal (current [A] or load [%]).
    pub signal: f64,
    /// Standard error of the mean signal.
    pub signal_se: f64,
}

/// One fitted line.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// Holds from this speed [rpm] (0 for the first line: it covers everything below).
    pub from_rpm: f64,
    /// `(intercept, slope)` and their uncertainties.
    pub fit: LinearFit,
    /// Points on this line.
    pub points: usize,
}

/// The whole fit.
#[derive(Clone, Debug, PartialEq)]
pub struct IdleFit {
    /// Points used, sorted by speed.
    pub points: Vec<SpeedPoint>,
    /// Lines in speed order.
    pub pieces: Vec<Piece>,
    /// Whether the breaks were chosen here (else given).
    pub auto_breaks: bool,
    /// The model with its idle lines replaced.
    pub model: SpindleModel,
}

/// Steady-speed points of every file, through the Monitor of `cfg`.
pub fn speed_points(
    files: &[PathBuf],
    cfg: &MonitorConfig,
    rel_tol: f64,
    min_s: f64,
) -> Result<Vec<SpeedPoint>> {
    let Input::Motor { spindle, .. } = &cfg.input else {
        bail!(
            "spindle idle calibration needs a motor input (`[input.motor...]`), not a dynamometer"
        );
    };
    let zero = zero_idle(spindle);
    let radius = cfg.estimator.tool.radius_mm;
    let mut out = Vec::new();
    for file in files {
        let mut reader = TraceReader::open(file)?;
        let mut c = cfg.clone();
        if let Input::Motor { spindle, .. } = &mut c.input {
            *spindle = zero.clone();
        }
        // A sweep without feed needs no velocity columns.
        if !reader.kind().has_velocity {
            c.feed_velocity = FeedVelocity::Nominal([0.0, 0.0]);
        }
        if let Some(rate) = reader.detect_sample_rate_hz()? {
            c.sample_rate_hz = rate as f32;
        }
        let rate = f64::from(c.sample_rate_hz);
        let mut teeth: Vec<(f64, f64, f64, f64)> = Vec::new();
        replay::replay(&mut reader, &c, |rec, _| {
            if rec.status.intersects(BAD) {
                teeth.push((f64::NAN, f64::NAN, f64::NAN, f64::NAN));
            } else {
                let signal = zero.signal_for_force(rec.f2_n, rec.rpm, radius);
                teeth.push((
                    rec.time_s(rate as f32),
                    f64::from(rec.rpm),
                    f64::from(signal),
                    f64::from(rec.samples),
                ));
            }
        })
        .with_context(|| format!("{}", file.display()))?;
        // Steady stretches: consecutive good teeth within `rel_tol` of the stretch's mean
        // speed so far, or of two samples of period (a period is a whole number of samples,
        // so the per-tooth speed jitters by one sample in `samples`).
        let mut start = 0;
        let mut sum = 0.0;
        for i in 0..=teeth.len() {
            let ends = match teeth.get(i) {
                None => true,
                Some(t) if !t.1.is_finite() => true,
                Some(t) if i > start => {
                    let m = sum / (i - start) as f64;
                    (t.1 - m).abs() > m * rel_tol.max(2.0 / t.3)
                }
                Some(_) => false,
            };
            if ends {
                if let Some(p) = steady_point(&teeth[start..i], min_s, file) {
                    out.push(p);
                }
                // A bad tooth starts nothing; a good one starts the next stretch.
                start = if teeth.get(i).is_some_and(|t| t.1.is_finite()) {
                    i
                } else {
                    i + 1
                };
                sum = 0.0;
            }
            if let Some(t) = teeth.get(i).filter(|t| t.1.is_finite()) {
                sum += t.1;
            }
        }
    }
    out.sort_by(|a, b| a.rpm.total_cmp(&b.rpm));
    Ok(out)
}

/// The mean of a stretch after dropping its first quarter (spin-up, signal lag).
fn steady_point(
    teeth: &[(f64, f64, f64, f64)],
    min_s: f64,
    file: &std::path::Path,
) -> Option<SpeedPoint> {
    let kept = teeth.get(teeth.len() / 4..)?;
    let (first, last) = (kept.first()?, kept.last()?);
    if !first.0.is_finite() || last.0 - first.0 < min_s || kept.len() < 8 {
        return None;
    }
    let n = kept.len() as f64;
    // The harmonic mean: the speed of the mean period. Periods are whole samples, and the
    // plain mean of their reciprocals is biased upwards where they alternate (12, 13, ...).
    let rpm = n / kept.iter().map(|t| 1.0 / t.1).sum::<f64>();
    let signal = kept.iter().map(|t| t.2).sum::<f64>() / n;
    let var = kept.iter().map(|t| (t.2 - signal).powi(2)).sum::<f64>() / (n - 1.0);
    Some(SpeedPoint {
        file: file.to_path_buf(),
        from_s: first.0,
        to_s: last.0,
        rpm,
        signal,
        signal_se: (var / n).sqrt(),
    })
}

/// The model with a zero idle line (what the Monitor subtracts becomes nothing).
fn zero_idle(model: &SpindleModel) -> SpindleModel {
    let zero = Segments::from_array([Segment {
        from_rpm: 0.0,
        slope: 0.0,
        intercept: 0.0,
    }]);
    let mut m = model.clone();
    match &mut m {
        SpindleModel::Current { idle_current_a, .. } => *idle_current_a = zero,
        SpindleModel::Load { idle_load_pct, .. } => *idle_load_pct = zero,
    }
    m
}

/// Fits lines between `breaks` [rpm] (sorted), or chooses the breaks (`None`).
pub fn fit_idle(
    points: Vec<SpeedPoint>,
    breaks: Option<&[f64]>,
    base: &SpindleModel,
) -> Result<IdleFit> {
    if points.len() < 2 {
        bail!(
            "spindle idle: {} steady speed(s) found; a sweep needs at least two (hold each \
             speed for a second or more)",
            points.len()
        );
    }
    let (bounds, auto) = match breaks {
        Some(b) => (b.to_vec(), false),
        None => (choose_breaks(&points), true),
    };
    if bounds.len() + 1 > SEGMENTS_CAPACITY {
        bail!(
            "spindle idle: {} breaks give {} lines; the core holds at most {SEGMENTS_CAPACITY}",
            bounds.len(),
            bounds.len() + 1
        );
    }
    let pieces = fit_pieces(&points, &bounds)?;
    let lines: Vec<Segment> = pieces
        .iter()
        .map(|p| Segment {
            from_rpm: p.from_rpm as f32,
            slope: p.fit.coef[1] as f32,
            intercept: p.fit.coef[0] as f32,
        })
        .collect();
    let segments =
        Segments::new(&lines).map_err(|e| anyhow!("spindle idle: fitted lines refused: {e}"))?;
    let mut model = base.clone();
    match &mut model {
        SpindleModel::Current { idle_current_a, .. } => *idle_current_a = segments,
        SpindleModel::Load { idle_load_pct, .. } => *idle_load_pct = segments,
    }
    Ok(IdleFit {
        points,
        pieces,
        auto_breaks: auto,
        model,
    })
}

/// One line per interval between `bounds`; an interval with a single speed gets a
/// constant.
fn fit_pieces(points: &[SpeedPoint], bounds: &[f64]) -> Result<Vec<Piece>> {
    let mut edges = vec![f64::NEG_INFINITY];
    edges.extend_from_slice(bounds);
    edges.push(f64::INFINITY);
    let mut pieces = Vec::new();
    for (k, w) in edges.windows(2).enumerate() {
        let pts: Vec<&SpeedPoint> = points
            .iter()
            .filter(|p| p.rpm >= w[0] && p.rpm < w[1])
            .collect();
        if pts.is_empty() {
            bail!(
                "spindle idle: no steady speed between {} and {} rpm: move the break or add \
                 speeds there",
                w[0].max(0.0),
                w[1]
            );
        }
        let distinct = pts
            .iter()
            .any(|p| (p.rpm - pts[0].rpm).abs() > 1e-3 * pts[0].rpm);
        let fit = if distinct {
            let a: Vec<f64> = pts.iter().flat_map(|p| [1.0, p.rpm]).collect();
            let y: Vec<f64> = pts.iter().map(|p| p.signal).collect();
            fit_linear(&a, 2, &y).with_context(|| format!("spindle idle line {k}"))?
        } else {
            let a = vec![1.0; pts.len()];
            let y: Vec<f64> = pts.iter().map(|p| p.signal).collect();
            let mut f = fit_linear(&a, 1, &y)?;
            f.coef.push(0.0);
            f.se.push(0.0);
            f.ci95.push(0.0);
            f
        };
        pieces.push(Piece {
            from_rpm: if k == 0 { 0.0 } else { w[0] },
            fit,
            points: pts.len(),
        });
    }
    Ok(pieces)
}

/// Breaks by BIC over one to three lines, each through at least three speeds; a break sits
/// midway between the speeds either side of it.
fn choose_breaks(points: &[SpeedPoint]) -> Vec<f64> {
    let n = points.len();
    let gaps: Vec<f64> = (1..n)
        .filter(|&i| points[i].rpm > points[i - 1].rpm * 1.001)
        .map(|i| 0.5 * (points[i].rpm + points[i - 1].rpm))
        .collect();
    // The residual floor: the points' own scatter, so that noise-free data does not buy
    // a line per point with log(0).
    let mut se: Vec<f64> = points.iter().map(|p| p.signal_se).collect();
    se.sort_by(f64::total_cmp);
    let floor = se[se.len() / 2].max(1e-9).powi(2);
    let bic = |bounds: &[f64]| -> Option<f64> {
        let pieces = fit_pieces(points, bounds).ok()?;
        // Three speeds a line at least: two would fit exactly and always look better.
        if pieces.iter().any(|p| p.points < 3) {
            return None;
        }
        let ssr: f64 = pieces
            .iter()
            .flat_map(|p| p.fit.residuals.iter())
            .map(|r| r * r)
            .sum();
        let k = (3 * pieces.len() - 1) as f64;
        let nf = n as f64;
        Some(nf * (ssr / nf).max(floor).ln() + k * nf.ln())
    };
    let mut best: (f64, Vec<f64>) = (bic(&[]).unwrap_or(f64::INFINITY), Vec::new());
    for (i, &g1) in gaps.iter().enumerate() {
        if let Some(b) = bic(&[g1]) {
            if b < best.0 {
                best = (b, vec![g1]);
            }
        }
        for &g2 in &gaps[i + 1..] {
            if let Some(b) = bic(&[g1, g2]) {
                if b < best.0 {
                    best = (b, vec![g1, g2]);
                }
            }
        }
    }
    best.1
}
