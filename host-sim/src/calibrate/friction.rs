//! `calibrate friction`: the idle (air-cut) current of each feed axis against its velocity.
//!
//! The core's feed axis (`estimator_core::drive::FeedAxis`) reads a cutting load as
//! `F = k_f (i - i0) - (F_c sgn(v) + b v)`, `k_f = sign 2 pi eta K_t / L`. In an air move
//! the load is zero, so the current is
//!
//! ```text
//! i = i0 + (F_c / k_f) sgn(v) + (b / k_f) v
//! ```
//!
//! linear in `(i0, F_c, b)`: one least-squares fit per axis over the steady stretches of
//! air moves at several velocities in both directions. Both directions are needed to
//! tell the offset `i0` (sensor offset, gravity on a vertical axis) from Coulomb friction;
//! two speeds per direction to tell Coulomb from viscous. `k_f` comes from the machine
//! file (motor and screw data), so the fit is of friction, not of the drive's gain: a gain
//! error cancels here (an air move has no load) and shows only in the cutting calibration.

use super::stats::{fit_linear, LinearFit};
use crate::trace::{FeedSignal, TraceReader};
use anyhow::{bail, Context, Result};
use estimator_core::drive::FeedAxis;
use std::path::{Path, PathBuf};

/// How steady stretches are found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Steady {
    /// A stretch goes on while each axis' velocity stays within this share of its value
    /// at the stretch's start (or [`Steady::abs_tol_mm_min`], whichever is larger).
    pub rel_tol: f64,
    /// Absolute velocity tolerance [mm/min].
    pub abs_tol_mm_min: f64,
    /// Shortest stretch used [s] (after trimming).
    pub min_s: f64,
    /// Share of each stretch dropped at its start (acceleration, current-loop settling).
    pub trim_start: f64,
}

impl Default for Steady {
    fn default() -> Self {
        Steady {
            rel_tol: 0.02,
            abs_tol_mm_min: 1.0,
            min_s: 0.2,
            trim_start: 0.25,
        }
    }
}

/// Mean current of one axis over one steady stretch.
#[derive(Clone, Debug, PartialEq)]
pub struct AirPoint {
    /// Where it came from.
    pub file: PathBuf,
    /// Start and end of the part averaged [s].
    pub from_s: f64,
    /// End [s].
    pub to_s: f64,
    /// Mean velocity [mm/min].
    pub velocity_mm_min: f64,
    /// Mean current [A].
    pub current_a: f64,
    /// Standard deviation of the current over the stretch [A].
    pub current_sd_a: f64,
}

/// The fit of one axis.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisFit {
    /// 0 = X, 1 = Y.
    pub axis: usize,
    /// The points it used.
    pub points: Vec<AirPoint>,
    /// `(i0 [A], F_c / k_f [A], b / k_f [A per mm/min])` with their uncertainties.
    pub fit: LinearFit,
    /// The axis with `current_offset_a`, `coulomb_n`, `viscous_n_per_mm_min` replaced.
    pub axis_out: FeedAxis,
    /// 95 % half-widths of `(i0 [A], F_c [N], b [N per mm/min])`.
    pub ci95: [f64; 3],
    /// Notes for the report (a clamped term).
    pub notes: Vec<String>,
}

/// Finds the steady stretches of every file, per axis (`axes` axes read).
pub fn air_points(files: &[PathBuf], axes: usize, steady: &Steady) -> Result<[Vec<AirPoint>; 2]> {
    let mut out: [Vec<AirPoint>; 2] = [Vec::new(), Vec::new()];
    for file in files {
        let mut r = TraceReader::open(file)?;
        let kind = r.kind();
        let name = file.display();
        if kind.feed != FeedSignal::Current {
            bail!("{name}: feed friction needs motor currents (`feed_x_a`), not forces");
        }
        if !kind.has_velocity {
            bail!(
                "{name}: feed friction needs the feed velocity (`feed_vx_mm_min` column): record \
                 the air moves with the feed encoder, or add the programmed velocity column"
            );
        }
        let n_axes = if kind.two_axis { axes } else { 1 };
        // The current stretch: (time, velocity, current) per row.
        let mut run: Vec<(f64, [f32; 2], [f32; 2])> = Vec::new();
        let close = |run: &mut Vec<(f64, [f32; 2], [f32; 2])>, out: &mut [Vec<AirPoint>; 2]| {
            if let Some(p) = stretch_points(run, n_axes, steady, file) {
                for (axis, point) in p.into_iter().enumerate() {
                    if let Some(point) = point {
                        out[axis].push(point);
                    }
                }
            }
            run.clear();
        };
        while let Some(row) = r.next_row().with_context(|| format!("{name}"))? {
            let v = row.feed_velocity_mm_min;
            let i = row.feed;
            if !(0..n_axes).all(|k| v[k].is_finite() && i[k].is_finite()) {
                // A gap in the data ends a stretch; the rows are not averaged.
                close(&mut run, &mut out);
                continue;
            }
            if let Some(&(_, v0, _)) = run.first() {
                let off = (0..n_axes).any(|k| {
                    let tol = (steady.rel_tol * f64::from(v0[k]).abs()).max(steady.abs_tol_mm_min);
                    f64::from(v[k] - v0[k]).abs() > tol
                });
                if off {
                    close(&mut run, &mut out);
                }
            }
            run.push((row.time_s, v, i));
        }
        close(&mut run, &mut out);
    }
    Ok(out)
}

/// The points of one stretch (`None` for an axis at rest), or none if it is too short.
fn stretch_points(
    run: &[(f64, [f32; 2], [f32; 2])],
    axes: usize,
    steady: &Steady,
    file: &Path,
) -> Option<[Option<AirPoint>; 2]> {
    let skip = (run.len() as f64 * steady.trim_start).ceil() as usize;
    let kept = run.get(skip..)?;
    let (first, last) = (kept.first()?.0, kept.last()?.0);
    if last - first < steady.min_s {
        return None;
    }
    let n = kept.len() as f64;
    let mut pts: [Option<AirPoint>; 2] = [None, None];
    for (k, slot) in pts.iter_mut().enumerate().take(axes) {
        let v = kept.iter().map(|r| f64::from(r.1[k])).sum::<f64>() / n;
        let i = kept.iter().map(|r| f64::from(r.2[k])).sum::<f64>() / n;
        let sd = (kept
            .iter()
            .map(|r| (f64::from(r.2[k]) - i).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        *slot = Some(AirPoint {
            file: file.to_path_buf(),
            from_s: first,
            to_s: last,
            velocity_mm_min: v,
            current_a: i,
            current_sd_a: sd,
        });
    }
    Some(pts)
}

/// Fits one axis: points at rest (inside the stiction band) are left out.
pub fn fit_axis(axis: usize, base: &FeedAxis, points: &[AirPoint]) -> Result<AxisFit> {
    let name = ["X", "Y"][axis.min(1)];
    let band = f64::from(base.stiction_band_mm_min);
    let moving: Vec<AirPoint> = points
        .iter()
        .filter(|p| p.velocity_mm_min.abs() > band)
        .cloned()
        .collect();
    let pos = moving.iter().filter(|p| p.velocity_mm_min > 0.0).count();
    let neg = moving.len() - pos;
    if pos == 0 || neg == 0 {
        bail!(
            "axis {name}: air moves in both directions are needed to tell the current offset \
             from Coulomb friction (steady stretches found: {pos} positive, {neg} negative)"
        );
    }
    let speeds = |sign: f64| {
        let mut s: Vec<f64> = moving
            .iter()
            .map(|p| p.velocity_mm_min * sign)
            .filter(|v| *v > 0.0)
            .collect();
        s.sort_by(f64::total_cmp);
        s.dedup_by(|a, b| (*a - *b).abs() <= 0.05 * b.abs());
        s.len()
    };
    if speeds(1.0).max(speeds(-1.0)) < 2 {
        bail!(
            "axis {name}: at least two feed velocities (in one direction at least) are needed \
             to tell viscous from Coulomb friction"
        );
    }
    let a: Vec<f64> = moving
        .iter()
        .flat_map(|p| [1.0, p.velocity_mm_min.signum(), p.velocity_mm_min])
        .collect();
    let y: Vec<f64> = moving.iter().map(|p| p.current_a).collect();
    let fit = fit_linear(&a, 3, &y).with_context(|| format!("axis {name}"))?;
    let k_f = f64::from(base.force_per_amp_n_per_a());
    let (i0, fc, b) = (fit.coef[0], fit.coef[1] * k_f, fit.coef[2] * k_f);
    if fc < 0.0 {
        bail!(
            "axis {name}: the idle current falls in the direction of motion (Coulomb term \
             {fc:.1} N): the axis `sign` in the machine file is probably the wrong way round"
        );
    }
    let mut notes = Vec::new();
    let b = if b < 0.0 {
        notes.push(format!(
            "axis {name}: fitted viscous term {b:.3e} N per mm/min < 0 (noise on a small \
             term): set to 0"
        ));
        0.0
    } else {
        b
    };
    let axis_out = FeedAxis {
        current_offset_a: i0 as f32,
        coulomb_n: fc as f32,
        viscous_n_per_mm_min: b as f32,
        ..*base
    };
    axis_out
        .validate()
        .map_err(|e| anyhow::anyhow!("axis {name}: fitted parameters refused: {e}"))?;
    let ci95 = [
        fit.ci95[0],
        fit.ci95[1] * k_f.abs(),
        fit.ci95[2] * k_f.abs(),
    ];
    Ok(AxisFit {
        axis,
        points: moving,
        fit,
        axis_out,
        ci95,
        notes,
    })
}
