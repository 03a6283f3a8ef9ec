//! `replay --plot`: the per-tooth records over time as a PNG or SVG.
//!
//! # Design
//! Panels sharing the time axis: (1) forces, the tooth averages (thin, pale: runout makes
//! them alternate) and the Monitor's filtered ones (bold); (2, 3) estimated `d_r` and
//! `d_a` over the valid records with their ±2 sigma band, and the truth where the trace
//! has it; (4) a status strip marking every record that is not valid, coloured by its main
//! cause (the first flag of [`CAUSES`] it carries). Alarms are vertical lines through every
//! panel, from [`PlotData::alarms`]: the times replay's alarm events latched the output
//! (see the alarm hook in [`crate::replay`]).
//!
//! Rendering is in memory (plotters' bitmap backend into a buffer, encoded with `png`; or
//! the SVG backend into a string), so the caller writes the file with its usual
//! `.partial`-then-rename. Text uses DejaVu Sans compiled in (the `dejavu` crate, through
//! plotters' `ab_glyph` feature): no system fonts, no fontconfig.
//!
//! Note: more than [`MAX_LINE_POINTS`] records are thinned to every k-th for the lines and
//! bands (a picture has far fewer pixels); the status strip always sees every record.

use anyhow::{anyhow, bail, Result};
use estimator_core::{Status, ToothRecord};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

use crate::trace::Truth;

/// Image size [px].
pub const SIZE: (u32, u32) = (1600, 1150);
/// Most records drawn as lines.
pub const MAX_LINE_POINTS: usize = 20_000;

/// Non-valid causes in priority order (the first one present names a record's colour).
pub const CAUSES: [(Status, &str, RGBColor); 13] = [
    (Status::NO_SYNC, "no sync", RGBColor(120, 0, 120)),
    (
        Status::PERIOD_INVALID,
        "period invalid",
        RGBColor(200, 0, 200),
    ),
    (Status::WINDOW_MOVED, "window moved", RGBColor(255, 0, 120)),
    (Status::INPUT_FAULT, "input fault", RGBColor(200, 0, 0)),
    (Status::NON_FINITE, "non-finite", RGBColor(120, 0, 0)),
    (Status::NOT_CUTTING, "not cutting", RGBColor(170, 170, 170)),
    (Status::FEED_CHANGE, "feed change", RGBColor(0, 150, 200)),
    (Status::TRANSIENT, "transient", RGBColor(240, 150, 0)),
    (Status::SETTLING, "settling", RGBColor(250, 210, 80)),
    (Status::RR_CLAMPED, "R_r clamped", RGBColor(0, 120, 0)),
    (Status::RA_CLAMPED, "R_a clamped", RGBColor(90, 180, 90)),
    (
        Status::TC_OUT_OF_RANGE,
        "t_c out of range",
        RGBColor(60, 60, 200),
    ),
    (Status::AMBIGUOUS, "ambiguous", RGBColor(140, 100, 60)),
];

/// Flags that make a record's tooth averages meaningless (not plotted as forces).
const NO_AVERAGE: Status = Status(
    Status::NO_SYNC.0
        | Status::PERIOD_INVALID.0
        | Status::WINDOW_MOVED.0
        | Status::INPUT_FAULT.0
        | Status::NON_FINITE.0,
);

/// Index in [`CAUSES`] of the main reason a record is not valid; `None` if valid;
/// `Some(CAUSES.len())` for bits no name covers.
pub fn main_cause(s: Status) -> Option<usize> {
    if s.is_valid() {
        return None;
    }
    Some(
        CAUSES
            .iter()
            .position(|(f, _, _)| s.contains(*f))
            .unwrap_or(CAUSES.len()),
    )
}

/// One record to plot.
#[derive(Clone, Copy, Debug)]
pub struct PlotPoint {
    /// End time of the period [s].
    pub time_s: f64,
    /// The Monitor's record.
    pub record: ToothRecord,
    /// Truth at the record's end sample (NaN where unknown).
    pub truth: Truth,
}

/// Everything a plot shows.
#[derive(Clone, Debug, Default)]
pub struct PlotData {
    /// Title line (the trace's name).
    pub title: String,
    /// Dynamometer input: the second force is `F_ay`, not `F_at`.
    pub dynamometer: bool,
    /// The records, in time order.
    pub points: Vec<PlotPoint>,
    /// Alarm times [s] (vertical lines): when replay's alarm events latched the output.
    pub alarms: Vec<f64>,
}

/// Output format, from the file name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFormat {
    /// Bitmap.
    Png,
    /// Vector.
    Svg,
}

impl PlotFormat {
    /// `.png` or `.svg` (any case); anything else is an error.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(PlotFormat::Png),
            Some("svg") => Ok(PlotFormat::Svg),
            _ => bail!("{}: the plot file must end in .png or .svg", path.display()),
        }
    }
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Only fails for bytes that are not a font; the embedded one is.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Renders `data` as a complete PNG or SVG file's bytes.
pub fn render(data: &PlotData, format: PlotFormat) -> Result<Vec<u8>> {
    if data.points.is_empty() {
        bail!("no tooth records to plot (no sync pulses in the trace?)");
    }
    register_font();
    let (w, h) = SIZE;
    match format {
        PlotFormat::Png => {
            let mut rgb = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
                draw(&root, data)?;
                root.present().map_err(pe)?;
            }
            let mut out = Vec::new();
            let mut enc = png::Encoder::new(&mut out, w, h);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut wr = enc
                .write_header()
                .map_err(|e| anyhow!("encoding the PNG: {e}"))?;
            wr.write_image_data(&rgb)
                .map_err(|e| anyhow!("encoding the PNG: {e}"))?;
            wr.finish().map_err(|e| anyhow!("encoding the PNG: {e}"))?;
            Ok(out)
        }
        PlotFormat::Svg => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, (w, h)).into_drawing_area();
                draw(&root, data)?;
                root.present().map_err(pe)?;
            }
            Ok(s.into_bytes())
        }
    }
}

/// A plotters error as an anyhow one.
fn pe<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing the plot: {e}")
}

/// `(lo, hi)` of the finite values with a 5 % margin; `(0, 1)` when there are none.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-3 * hi.abs().max(1.0));
    (lo - pad, hi + pad)
}

/// Splits `points` into runs of consecutive records for which `keep` holds.
fn runs(points: &[PlotPoint], keep: impl Fn(&PlotPoint) -> bool) -> Vec<&[PlotPoint]> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, p) in points.iter().enumerate() {
        match (keep(p), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push(&points[s..i]);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push(&points[s..]);
    }
    out
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, data: &PlotData) -> Result<()> {
    root.fill(&WHITE).map_err(pe)?;
    let all = &data.points;
    let stride = all.len().div_ceil(MAX_LINE_POINTS).max(1);
    let pts: Vec<PlotPoint> = all.iter().step_by(stride).copied().collect();
    let t0 = all.first().map_or(0.0, |p| p.time_s);
    let mut t1 = all.last().map_or(1.0, |p| p.time_s);
    if t1 <= t0 {
        t1 = t0 + 1.0;
    }
    let (title, rest) = root.split_vertically(40);
    let valid = all.iter().filter(|p| p.record.status.is_valid()).count();
    title
        .titled(
            &format!(
                "{}: {} tooth records, {} valid{}",
                data.title,
                all.len(),
                valid,
                if data.alarms.is_empty() {
                    String::new()
                } else {
                    format!(", {} alarms", data.alarms.len())
                }
            ),
            ("sans-serif", 22),
        )
        .map_err(pe)?;
    let (forces, rest) = rest.split_vertically(330);
    let (dr, rest) = rest.split_vertically(270);
    let (da, status) = rest.split_vertically(270);
    let second = if data.dynamometer { "F_ay" } else { "F_at" };

    // --- forces ---
    let ok_avg = |p: &PlotPoint| !p.record.status.intersects(NO_AVERAGE);
    let (ylo, yhi) = range(pts.iter().filter(|p| ok_avg(p)).flat_map(|p| {
        let r = &p.record;
        [r.fx_n, r.f2_n, r.fx_filt_n, r.f2_filt_n].map(f64::from)
    }));
    let mut chart = ChartBuilder::on(&forces)
        .margin(8)
        .x_label_area_size(28)
        .y_label_area_size(70)
        .caption("tooth-average forces [N]", ("sans-serif", 18))
        .build_cartesian_2d(t0..t1, ylo..yhi)
        .map_err(pe)?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(pe)?;
    let series: [ForceSeries; 4] = [
        ("F_ax tooth", RGBColor(150, 170, 240), 1, |r| r.fx_n, true),
        ("tooth2", RGBColor(240, 160, 150), 1, |r| r.f2_n, true),
        (
            "F_ax filtered",
            RGBColor(0, 40, 200),
            2,
            |r| r.fx_filt_n,
            false,
        ),
        ("filtered2", RGBColor(200, 20, 0), 2, |r| r.f2_filt_n, false),
    ];
    for (i, (label, color, width, get, raw)) in series.into_iter().enumerate() {
        let label = match i {
            1 => format!("{second} tooth"),
            3 => format!("{second} filtered"),
            _ => label.to_string(),
        };
        let style = color.stroke_width(width);
        let mut first = true;
        let keep = |p: &PlotPoint| {
            if raw {
                ok_avg(p)
            } else {
                has_filtered(&p.record)
            }
        };
        for run in runs(&pts, keep) {
            let s = chart
                .draw_series(LineSeries::new(
                    run.iter().map(|p| (p.time_s, get(&p.record) as f64)),
                    style,
                ))
                .map_err(pe)?;
            if first {
                s.label(label.clone()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(3))
                });
                first = false;
            }
        }
    }
    alarm_lines(&mut chart, &data.alarms, (ylo, yhi))?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(pe)?;

    // --- depths ---
    type Get = fn(&PlotPoint) -> (f32, f32, f32);
    let panels: [(&DrawingArea<DB, Shift>, &str, Get); 2] = [
        (&dr, "radial depth d_r [mm]", |p| {
            (p.record.dr_mm, p.record.dr_sigma_mm, p.truth.dr_mm)
        }),
        (&da, "axial depth d_a [mm]", |p| {
            (p.record.da_mm, p.record.da_sigma_mm, p.truth.da_mm)
        }),
    ];
    for (area, caption, get) in panels {
        depth_panel(area, caption, &pts, get, (t0, t1), &data.alarms)?;
    }

    // --- status strip ---
    status_strip(&status, all, (t0, t1), &data.alarms)?;
    Ok(())
}

/// A force line: label, colour, width, the value, whether it is a raw tooth average.
type ForceSeries = (&'static str, RGBColor, u32, fn(&ToothRecord) -> f32, bool);

/// Whether the record's filtered values mean anything yet: the Monitor starts them at 0
/// and holds the last ones through invalid periods.
fn has_filtered(r: &ToothRecord) -> bool {
    r.fx_filt_n != 0.0 || r.f2_filt_n != 0.0
}

fn alarm_lines<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    alarms: &[f64],
    (ylo, yhi): (f64, f64),
) -> Result<()> {
    for &t in alarms {
        chart
            .draw_series(LineSeries::new([(t, ylo), (t, yhi)], RED.stroke_width(2)))
            .map_err(pe)?;
    }
    Ok(())
}

fn depth_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    pts: &[PlotPoint],
    get: fn(&PlotPoint) -> (f32, f32, f32),
    (t0, t1): (f64, f64),
    alarms: &[f64],
) -> Result<()> {
    let valid = |p: &PlotPoint| p.record.status.is_valid();
    let (ylo, yhi) = range(pts.iter().flat_map(|p| {
        let (v, s, t) = get(p);
        let est = if valid(p) {
            [v - 2.0 * s, v + 2.0 * s]
        } else {
            [f32::NAN; 2]
        };
        [est[0], est[1], t].map(f64::from)
    }));
    // From 0, with room above the data for the legend.
    let (ylo, yhi) = (ylo.min(0.0), yhi + 0.25 * (yhi - ylo.min(0.0)));
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(28)
        .y_label_area_size(70)
        .caption(caption, ("sans-serif", 18))
        .build_cartesian_2d(t0..t1, ylo..yhi)
        .map_err(pe)?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(pe)?;
    let band_color = RGBColor(0, 90, 220);
    let mut first = true;
    for run in runs(pts, valid) {
        let mut poly: Vec<(f64, f64)> = run
            .iter()
            .map(|p| {
                let (v, s, _) = get(p);
                (p.time_s, f64::from(v + 2.0 * s))
            })
            .collect();
        poly.extend(run.iter().rev().map(|p| {
            let (v, s, _) = get(p);
            (p.time_s, f64::from(v - 2.0 * s))
        }));
        let band = chart
            .draw_series(std::iter::once(Polygon::new(
                poly,
                band_color.mix(0.25).filled(),
            )))
            .map_err(pe)?;
        if first {
            band.label("±2 sigma").legend(move |(x, y)| {
                Rectangle::new([(x, y - 5), (x + 18, y + 5)], band_color.mix(0.25).filled())
            });
        }
        let line = chart
            .draw_series(LineSeries::new(
                run.iter().map(|p| (p.time_s, f64::from(get(p).0))),
                band_color.stroke_width(2),
            ))
            .map_err(pe)?;
        if first {
            line.label("estimate (valid records)")
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], band_color.stroke_width(3))
                });
            first = false;
        }
    }
    let mut first = true;
    for run in runs(pts, |p| get(p).2.is_finite()) {
        let s = chart
            .draw_series(DashedLineSeries::new(
                run.iter().map(|p| (p.time_s, f64::from(get(p).2))),
                6,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(pe)?;
        if first {
            s.label("truth (dashed)").legend(|(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], BLACK.stroke_width(2))
            });
            first = false;
        }
    }
    alarm_lines(&mut chart, alarms, (ylo, yhi))?;
    if pts.iter().any(valid) || pts.iter().any(|p| get(p).2.is_finite()) {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(pe)?;
    } else {
        let (w, h) = area.dim_in_pixel();
        area.draw(&Text::new(
            "no valid record",
            (w as i32 / 2 - 60, h as i32 / 2),
            ("sans-serif", 20)
                .into_font()
                .color(&RGBColor(120, 120, 120)),
        ))
        .map_err(pe)?;
    }
    Ok(())
}

fn status_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    all: &[PlotPoint],
    (t0, t1): (f64, f64),
    alarms: &[f64],
) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(28)
        .y_label_area_size(70)
        .caption(
            "records not valid, by main cause (alarms: red lines)",
            ("sans-serif", 18),
        )
        .build_cartesian_2d(t0..t1, 0.0..1.0)
        .map_err(pe)?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .disable_y_mesh()
        .disable_y_axis()
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(pe)?;
    // Spans [start, end] of equal cause, merged across consecutive records.
    let mut spans: Vec<(usize, f64, f64)> = Vec::new();
    let mut prev_t = t0;
    for p in all {
        if let Some(c) = main_cause(p.record.status) {
            match spans.last_mut() {
                Some((lc, _, end)) if *lc == c && *end == prev_t => *end = p.time_s,
                _ => spans.push((c, prev_t, p.time_s)),
            }
        }
        prev_t = p.time_s;
    }
    let colors = |c: usize| CAUSES.get(c).map_or(BLACK, |x| x.2);
    for c in 0..=CAUSES.len() {
        let mine: Vec<_> = spans.iter().filter(|s| s.0 == c).collect();
        if mine.is_empty() {
            continue;
        }
        let color = colors(c);
        let name = CAUSES.get(c).map_or("other", |x| x.1);
        chart
            .draw_series(mine.iter().map(|(_, a, b)| {
                // At least a hair wide, so a single record shows.
                let b = b.max(a + (t1 - t0) * 5e-4);
                Rectangle::new([(*a, 0.15), (b, 0.85)], color.filled())
            }))
            .map_err(pe)?
            .label(name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], color.filled()));
    }
    alarm_lines(&mut chart, alarms, (0.0, 1.0))?;
    if !spans.is_empty() {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(pe)?;
    }
    Ok(())
}

/// One panel of [`render_fits`]: measured points and the fitted curves through them.
#[derive(Clone, Debug, Default)]
pub struct FitPanel {
    /// Caption.
    pub title: String,
    /// Axis labels `(x, y)`.
    pub labels: (String, String),
    /// Measured points.
    pub points: Vec<(f64, f64)>,
    /// Fitted curves, each a polyline.
    pub curves: Vec<Vec<(f64, f64)>>,
    /// Logarithmic axes (power laws).
    pub log: bool,
}

/// Renders calibration fits as an SVG, one panel per fit, stacked.
pub fn render_fits(title: &str, panels: &[FitPanel]) -> Result<String> {
    register_font();
    let (w, ph) = (SIZE.0, 320u32);
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, (w, 40 + ph * panels.len().max(1) as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(pe)?;
        let (head, mut rest) = root.split_vertically(40);
        head.titled(title, ("sans-serif", 22)).map_err(pe)?;
        for p in panels {
            let (area, below) = rest.split_vertically(ph);
            rest = below;
            let all = || p.points.iter().chain(p.curves.iter().flatten());
            let tf = |v: f64| if p.log { v.abs().max(1e-12).log10() } else { v };
            let (x0, x1) = range(all().map(|q| tf(q.0)));
            let (y0, y1) = range(all().map(|q| tf(q.1)));
            let (xl, yl) = if p.log {
                (
                    format!("log10 {}", p.labels.0),
                    format!("log10 {}", p.labels.1),
                )
            } else {
                p.labels.clone()
            };
            let mut chart = ChartBuilder::on(&area)
                .margin(8)
                .x_label_area_size(36)
                .y_label_area_size(70)
                .caption(&p.title, ("sans-serif", 18))
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(pe)?;
            chart
                .configure_mesh()
                .x_desc(xl)
                .y_desc(yl)
                .draw()
                .map_err(pe)?;
            for c in &p.curves {
                chart
                    .draw_series(LineSeries::new(c.iter().map(|q| (tf(q.0), tf(q.1))), &BLUE))
                    .map_err(pe)?;
            }
            chart
                .draw_series(
                    p.points
                        .iter()
                        .map(|q| Circle::new((tf(q.0), tf(q.1)), 4, RED.filled())),
                )
                .map_err(pe)?;
        }
        root.present().map_err(pe)?;
    }
    Ok(s)
}
