//! The toolpath: where the tool tip is at each instant, and how fast the spindle turns.
//!
//! Two sources, both turned into a list of timed [`Segment`]s:
//! - **G-code** (mm, XY plane): `G0 G1 G2 G3` (arcs by `I J` centre offsets or `R`, with an
//!   optional Z move: helix), `G4 P<seconds>` (dwell), `G90/G91` (absolute/relative),
//!   `G90.1/G91.1` (arc centres absolute/relative), `G17 G21 G94`, `F` (mm/min), `S` (rpm),
//!   `M3/M5` (spindle on/off), `M2/M30` (end). Ignored: `N O T H`, `M0 M1 M6 M7 M8 M9`,
//!   `G40 G43 G49 G54-G59 G61 G64 G80`, comments `( )` and `;`. Anything else (inches,
//!   other planes, inverse-time feed, counter-clockwise spindle, canned cycles) is an error
//!   naming the file and line: a silently misread program gives a plausible, wrong trace.
//!   The feed is taken as reached at once (no acceleration), as the paper's offline
//!   simulation does; `G0` moves in a straight line at the rapid rate.
//! - **CSV** of timed tool-tip positions, as a CNC streams them at 20-50 Hz (paper 004):
//!   header `time_s,x_mm,y_mm,z_mm,spindle_rpm` (other columns ignored), time strictly
//!   increasing; positions are linearly interpolated between rows, the spindle speed of a
//!   row holds until the next.

use anyhow::{anyhow, bail, Context, Result};
use std::f64::consts::{PI, TAU};
use std::path::Path;

/// A circular (or helical) move in the XY plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    /// Centre [mm].
    pub centre: [f64; 2],
    /// Radius at the start and at the end [mm] (equal but for rounding in the program).
    pub r0: f64,
    /// Radius at the end [mm].
    pub r1: f64,
    /// Angle of the start point seen from the centre [rad].
    pub a0: f64,
    /// Signed sweep [rad]: positive counter-clockwise (G3), negative clockwise (G2).
    pub sweep: f64,
}

/// One timed move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Start time [s].
    pub t0: f64,
    /// Duration [s] (> 0).
    pub dur: f64,
    /// Tool tip at the start [mm].
    pub p0: [f64; 3],
    /// Tool tip at the end [mm].
    pub p1: [f64; 3],
    /// Arc geometry, `None` for a straight move.
    pub arc: Option<Arc>,
    /// Spindle speed [rpm] during the move (0: stopped).
    pub rpm: f64,
    /// Whether this is a cutting-feed move (G1/G2/G3, or any CSV row), not a rapid/dwell.
    pub feed: bool,
    /// Source line (1-based) that programmed it.
    pub line: usize,
}

/// The tool's state at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathPoint {
    /// Tool tip [mm].
    pub pos: [f64; 3],
    /// Velocity [mm/s].
    pub vel: [f64; 3],
    /// Spindle speed [rpm].
    pub rpm: f64,
}

/// A whole toolpath.
#[derive(Clone, Debug, PartialEq)]
pub struct Toolpath {
    /// The moves, in time order, back to back.
    pub segments: Vec<Segment>,
    /// Time of the first instant [s].
    pub t_start: f64,
    /// Tool tip before the first move [mm].
    pub start: [f64; 3],
}

/// Settings for reading G-code.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GcodeOptions {
    /// Tool tip before the first move [mm].
    pub start: [f64; 3],
    /// Rate of `G0` moves [mm/min].
    pub rapid_mm_min: f64,
}

impl Segment {
    /// Position and velocity at fraction `u` in `[0, 1]` of the move.
    pub fn at(&self, u: f64) -> ([f64; 3], [f64; 3]) {
        let z = self.p0[2] + (self.p1[2] - self.p0[2]) * u;
        let vz = (self.p1[2] - self.p0[2]) / self.dur;
        match self.arc {
            None => {
                let mut p = [0.0; 3];
                let mut v = [0.0; 3];
                for i in 0..3 {
                    p[i] = self.p0[i] + (self.p1[i] - self.p0[i]) * u;
                    v[i] = (self.p1[i] - self.p0[i]) / self.dur;
                }
                (p, v)
            }
            Some(a) => {
                // Radius interpolated so that the move ends exactly on the programmed point.
                let r = a.r0 + (a.r1 - a.r0) * u;
                let ang = a.a0 + a.sweep * u;
                let (s, c) = ang.sin_cos();
                let w = a.sweep / self.dur;
                let dr = (a.r1 - a.r0) / self.dur;
                (
                    [a.centre[0] + r * c, a.centre[1] + r * s, z],
                    [-r * w * s + dr * c, r * w * c + dr * s, vz],
                )
            }
        }
    }

    /// Path length [mm].
    pub fn length(&self) -> f64 {
        let dz = self.p1[2] - self.p0[2];
        let planar = match self.arc {
            None => (self.p1[0] - self.p0[0]).hypot(self.p1[1] - self.p0[1]),
            Some(a) => a.sweep.abs() * 0.5 * (a.r0 + a.r1),
        };
        planar.hypot(dz)
    }
}

impl Toolpath {
    /// Time at the end of the last move [s].
    pub fn t_end(&self) -> f64 {
        self.segments.last().map_or(self.t_start, |s| s.t0 + s.dur)
    }

    /// The tool's state at time `t`. `cursor` remembers the segment of the last call, so
    /// that a run forward in time costs O(1) per call.
    pub fn sample(&self, t: f64, cursor: &mut usize) -> PathPoint {
        let segs = &self.segments;
        if segs.is_empty() {
            return PathPoint {
                pos: self.start,
                ..PathPoint::default()
            };
        }
        let mut i = (*cursor).min(segs.len() - 1);
        while i > 0 && t < segs[i].t0 {
            i -= 1;
        }
        while i + 1 < segs.len() && t >= segs[i].t0 + segs[i].dur {
            i += 1;
        }
        *cursor = i;
        let s = &segs[i];
        let u = ((t - s.t0) / s.dur).clamp(0.0, 1.0);
        let (pos, vel) = s.at(u);
        PathPoint {
            pos,
            vel,
            rpm: s.rpm,
        }
    }

    /// Total length and time of the feed (cutting) moves [mm, s].
    pub fn feed_totals(&self) -> (f64, f64) {
        self.segments
            .iter()
            .filter(|s| s.feed)
            .fold((0.0, 0.0), |(l, t), s| (l + s.length(), t + s.dur))
    }

    /// Reads a toolpath file: CSV if its name ends in `.csv`, G-code otherwise.
    pub fn load(path: &Path, opts: &GcodeOptions) -> Result<Toolpath> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read toolpath {file}"))?;
        let is_csv = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        if is_csv {
            Self::from_csv(&text, &file)
        } else {
            Self::from_gcode(&text, &file, opts)
        }
    }

    /// Parses a CSV of timed positions (see the module doc).
    pub fn from_csv(text: &str, file: &str) -> Result<Toolpath> {
        let mut rd = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let headers = rd
            .headers()
            .with_context(|| format!("{file}: cannot read the header line"))?
            .clone();
        let want = ["time_s", "x_mm", "y_mm", "z_mm", "spindle_rpm"];
        let mut col = [0usize; 5];
        for (slot, name) in col.iter_mut().zip(want) {
            *slot = headers.iter().position(|h| h == name).ok_or_else(|| {
                anyhow!(
                    "{file} line 1: no `{name}` column (need {})",
                    want.join(", ")
                )
            })?;
        }
        let mut rows: Vec<(usize, [f64; 5])> = Vec::new();
        for rec in rd.records() {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line() as usize);
                anyhow!("{file} line {line}: {e}")
            })?;
            let line = rec.position().map_or(0, |p| p.line() as usize);
            let mut v = [0.0; 5];
            for (k, (&c, name)) in col.iter().zip(want).enumerate() {
                let field = rec.get(c).unwrap_or("");
                v[k] = field
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        anyhow!("{file} line {line}: {name} `{field}` is not a finite number")
                    })?;
            }
            if v[4] < 0.0 {
                bail!("{file} line {line}: spindle_rpm {} is negative", v[4]);
            }
            if let Some((_, prev)) = rows.last() {
                if v[0] <= prev[0] {
                    bail!(
                        "{file} line {line}: time_s {} does not increase (previous row {})",
                        v[0],
                        prev[0]
                    );
                }
            }
            rows.push((line, v));
        }
        let Some(&(_, first)) = rows.first() else {
            bail!("{file}: no data rows");
        };
        let segments = rows
            .windows(2)
            .map(|w| {
                let (line, a) = w[0];
                let b = w[1].1;
                Segment {
                    t0: a[0],
                    dur: b[0] - a[0],
                    p0: [a[1], a[2], a[3]],
                    p1: [b[1], b[2], b[3]],
                    arc: None,
                    rpm: a[4],
                    feed: true,
                    line,
                }
            })
            .collect();
        Ok(Toolpath {
            segments,
            t_start: first[0],
            start: [first[1], first[2], first[3]],
        })
    }

    /// Parses G-code (see the module doc).
    pub fn from_gcode(text: &str, file: &str, opts: &GcodeOptions) -> Result<Toolpath> {
        if !(opts.rapid_mm_min.is_finite() && opts.rapid_mm_min > 0.0) {
            bail!("rapid rate must be > 0 mm/min");
        }
        let mut m = Machine {
            pos: opts.start,
            rapid_mm_min: opts.rapid_mm_min,
            motion: Motion::Rapid,
            absolute: true,
            arc_absolute: false,
            feed_mm_min: 0.0,
            rpm: 0.0,
            spindle_on: true,
            t: 0.0,
            segments: Vec::new(),
        };
        for (n, raw) in text.lines().enumerate() {
            let line = n + 1;
            let words = parse_words(raw).map_err(|e| anyhow!("{file}:{line}: {e}"))?;
            let end = m
                .execute(&words, line)
                .map_err(|e| anyhow!("{file}:{line}: {e}"))?;
            if end {
                break;
            }
        }
        Ok(Toolpath {
            segments: m.segments,
            t_start: 0.0,
            start: opts.start,
        })
    }
}

/// `letter value` pairs of one line, comments removed.
fn parse_words(raw: &str) -> Result<Vec<(char, f64)>> {
    let mut words = Vec::new();
    let mut chars = raw.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            ';' => break,
            '(' => {
                // Comment to the closing parenthesis.
                if !chars.by_ref().any(|c| c == ')') {
                    bail!("comment `(` is not closed");
                }
            }
            '%' | '/' => {}
            c if c.is_whitespace() => {}
            c if c.is_ascii_alphabetic() => {
                let letter = c.to_ascii_uppercase();
                while chars.peek().is_some_and(|c| c.is_whitespace()) {
                    chars.next();
                }
                let mut num = String::new();
                while let Some(&d) = chars.peek() {
                    if d.is_ascii_digit() || d == '.' || ((d == '-' || d == '+') && num.is_empty())
                    {
                        num.push(d);
                        chars.next();
                    } else {
                        break;
                    }
                }
                let v: f64 = num
                    .parse()
                    .map_err(|_| anyhow!("`{letter}` is not followed by a number"))?;
                words.push((letter, v));
            }
            other => bail!("unexpected character `{other}`"),
        }
    }
    Ok(words)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Motion {
    Rapid,
    Linear,
    Cw,
    Ccw,
}

/// The modal state of the G-code interpreter.
struct Machine {
    pos: [f64; 3],
    rapid_mm_min: f64,
    motion: Motion,
    absolute: bool,
    arc_absolute: bool,
    feed_mm_min: f64,
    rpm: f64,
    spindle_on: bool,
    t: f64,
    segments: Vec<Segment>,
}

/// G codes accepted and ignored: they change nothing the simulation models.
const IGNORED_G: &[f64] = &[
    40.0, 43.0, 49.0, 54.0, 55.0, 56.0, 57.0, 58.0, 59.0, 61.0, 64.0, 80.0,
];

impl Machine {
    fn spindle_rpm(&self) -> f64 {
        if self.spindle_on {
            self.rpm
        } else {
            0.0
        }
    }

    /// Runs one line; returns `true` at program end.
    fn execute(&mut self, words: &[(char, f64)], line: usize) -> Result<bool> {
        let mut target: [Option<f64>; 3] = [None; 3];
        let (mut i, mut j, mut r) = (None, None, None);
        let mut p = None;
        let mut dwell = false;
        let mut end = false;
        let mut motion_word = false;
        for &(letter, v) in words {
            match letter {
                'G' => {
                    let code = (v * 10.0).round() / 10.0;
                    match code {
                        0.0 => self.motion = Motion::Rapid,
                        1.0 => self.motion = Motion::Linear,
                        2.0 => self.motion = Motion::Cw,
                        3.0 => self.motion = Motion::Ccw,
                        4.0 => dwell = true,
                        17.0 | 21.0 | 94.0 => {}
                        18.0 | 19.0 => bail!("G{code}: only the XY plane (G17) is supported"),
                        20.0 => bail!("G20: inch units are not supported (use G21, mm)"),
                        90.0 => self.absolute = true,
                        91.0 => self.absolute = false,
                        90.1 => self.arc_absolute = true,
                        91.1 => self.arc_absolute = false,
                        93.0 | 95.0 => bail!("G{code}: only feed per minute (G94) is supported"),
                        c if IGNORED_G.contains(&c) => {}
                        c => bail!("G{c} is not supported"),
                    }
                    if matches!(code, 0.0..=3.0) {
                        motion_word = true;
                    }
                }
                'M' => match v.round() as i64 {
                    3 => self.spindle_on = true,
                    4 => bail!(
                        "M4 (counter-clockwise spindle) is not supported: the model is a \
                         right-hand cutter turning clockwise (M3)"
                    ),
                    5 => self.spindle_on = false,
                    2 | 30 => end = true,
                    0 | 1 | 6 | 7 | 8 | 9 => {}
                    c => bail!("M{c} is not supported"),
                },
                'X' => target[0] = Some(v),
                'Y' => target[1] = Some(v),
                'Z' => target[2] = Some(v),
                'I' => i = Some(v),
                'J' => j = Some(v),
                'R' => r = Some(v),
                'P' => p = Some(v),
                'F' => {
                    if !(v.is_finite() && v > 0.0) {
                        bail!("feed rate F{v} must be > 0 mm/min");
                    }
                    self.feed_mm_min = v;
                }
                'S' => {
                    if !(v.is_finite() && v >= 0.0) {
                        bail!("spindle speed S{v} must be >= 0 rpm");
                    }
                    self.rpm = v;
                }
                'N' | 'O' | 'T' | 'H' | 'D' => {}
                'K' => bail!("K is not supported (arcs are in the XY plane: use I and J)"),
                c => bail!("word `{c}` is not supported"),
            }
        }
        if dwell {
            let secs = p.ok_or_else(|| anyhow!("G4 needs P<seconds>"))?;
            if !(secs.is_finite() && secs >= 0.0) {
                bail!("G4 P{secs}: dwell must be >= 0 s");
            }
            self.push(self.pos, None, secs, false, line);
            return Ok(end);
        }
        let has_axis = target.iter().any(Option::is_some);
        if !has_axis {
            if motion_word
                && matches!(self.motion, Motion::Cw | Motion::Ccw)
                && (i.is_some() || j.is_some())
            {
                // A full circle back to the start point: `G2 I5` with no axis words.
            } else {
                if i.is_some() || j.is_some() || r.is_some() {
                    bail!("I, J or R without an arc move");
                }
                return Ok(end);
            }
        }
        let mut end_pos = self.pos;
        for (axis, t) in target.iter().enumerate() {
            if let Some(v) = t {
                end_pos[axis] = if self.absolute {
                    *v
                } else {
                    self.pos[axis] + v
                };
            }
        }
        match self.motion {
            Motion::Rapid | Motion::Linear => {
                if i.is_some() || j.is_some() || r.is_some() {
                    bail!("I, J or R on a straight move");
                }
                let seg_len = (0..3)
                    .map(|k| (end_pos[k] - self.pos[k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let rate = if self.motion == Motion::Rapid {
                    self.rapid_mm_min
                } else {
                    self.feed_rate()?
                };
                self.push(
                    end_pos,
                    None,
                    seg_len / rate * 60.0,
                    self.motion == Motion::Linear,
                    line,
                );
            }
            Motion::Cw | Motion::Ccw => {
                let ccw = self.motion == Motion::Ccw;
                let arc = self.arc(end_pos, i, j, r, ccw)?;
                let planar = arc.sweep.abs() * 0.5 * (arc.r0 + arc.r1);
                let len = planar.hypot(end_pos[2] - self.pos[2]);
                let rate = self.feed_rate()?;
                self.push(end_pos, Some(arc), len / rate * 60.0, true, line);
            }
        }
        Ok(end)
    }

    fn feed_rate(&self) -> Result<f64> {
        if self.feed_mm_min > 0.0 {
            Ok(self.feed_mm_min)
        } else {
            bail!("feed move with no feed rate set (F)")
        }
    }

    /// The geometry of an arc from the current position to `end`.
    fn arc(
        &self,
        end: [f64; 3],
        i: Option<f64>,
        j: Option<f64>,
        r: Option<f64>,
        ccw: bool,
    ) -> Result<Arc> {
        let (sx, sy) = (self.pos[0], self.pos[1]);
        let (ex, ey) = (end[0], end[1]);
        let centre = match (i.is_some() || j.is_some(), r) {
            (true, Some(_)) => bail!("arc with both I/J and R"),
            (false, None) => bail!("arc needs I/J or R"),
            (true, None) => {
                let (i, j) = (i.unwrap_or(0.0), j.unwrap_or(0.0));
                if self.arc_absolute {
                    [i, j]
                } else {
                    [sx + i, sy + j]
                }
            }
            (false, Some(r)) => {
                let (dx, dy) = (ex - sx, ey - sy);
                let d = dx.hypot(dy);
                if d < 1e-9 {
                    bail!(
                        "R arc with the end point equal to the start (use I/J for a full circle)"
                    );
                }
                if r.abs() < 0.5 * d - 1e-6 {
                    bail!("R{r} is smaller than half the chord ({:.4} mm)", 0.5 * d);
                }
                let h = (r * r - 0.25 * d * d).max(0.0).sqrt();
                // Left normal of the chord; a counter-clockwise minor arc (R > 0) has its
                // centre on the left, a clockwise one on the right, R < 0 the other side.
                let (nx, ny) = (-dy / d, dx / d);
                let side = if ccw == (r > 0.0) { 1.0 } else { -1.0 };
                [
                    0.5 * (sx + ex) + side * h * nx,
                    0.5 * (sy + ey) + side * h * ny,
                ]
            }
        };
        let r0 = (sx - centre[0]).hypot(sy - centre[1]);
        let r1 = (ex - centre[0]).hypot(ey - centre[1]);
        if r0 < 1e-6 {
            bail!("arc centre is on the start point");
        }
        if (r0 - r1).abs() > 0.005 + 1e-3 * r0 {
            bail!(
                "arc radius differs at start ({r0:.4} mm) and end ({r1:.4} mm): the end point is \
                 not on the circle"
            );
        }
        let a0 = (sy - centre[1]).atan2(sx - centre[0]);
        let a1 = (ey - centre[1]).atan2(ex - centre[0]);
        let mut sweep = if ccw {
            (a1 - a0).rem_euclid(TAU)
        } else {
            -(a0 - a1).rem_euclid(TAU)
        };
        // Same start and end: a full circle (with I/J; R refused above).
        if sweep.abs() < 1e-9 {
            sweep = if ccw { TAU } else { -TAU };
        }
        debug_assert!(sweep.abs() <= TAU + PI * 1e-9);
        Ok(Arc {
            centre,
            r0,
            r1,
            a0,
            sweep,
        })
    }

    fn push(&mut self, end: [f64; 3], arc: Option<Arc>, dur: f64, feed: bool, line: usize) {
        if dur > 0.0 && dur.is_finite() {
            self.segments.push(Segment {
                t0: self.t,
                dur,
                p0: self.pos,
                p1: end,
                arc,
                rpm: self.spindle_rpm(),
                feed,
                line,
            });
            self.t += dur;
        }
        self.pos = end;
    }
}

/// A rectangular pocket program: per level, a ramp entry, zig-zag roughing that leaves
/// `allowance` on the walls, and one climb-milling finishing lap along the wall that
/// removes it; rapid retract at the end. Used by the benchmark and the tests (written to
/// `tests/data/pocket_60x40.nc`).
///
/// The pocket spans `[x0, x0 + w] x [y0, y0 + h]`, from `z = 0` down to `-depth` in
/// levels of `step_down`; the tool of radius `r` roughs it with stepover `stepover`.
#[allow(clippy::too_many_arguments)]
pub fn pocket_program(
    [x0, y0]: [f64; 2],
    [w, h]: [f64; 2],
    depth: f64,
    step_down: f64,
    r: f64,
    stepover: f64,
    allowance: f64,
    feed_mm_min: f64,
    rpm: f64,
) -> String {
    let mut lines: Vec<String> = vec![
        format!(
            "(pocket {w} x {h} x {depth} mm at X{x0} Y{y0}, tool R{r}: {step_down} mm levels, \
             stepover {stepover}, wall allowance {allowance}, F{feed_mm_min} S{rpm})"
        ),
        "G21 G17 G90 G94".into(),
        format!("S{rpm} M3"),
        "G0 Z5".into(),
    ];
    // Tool-centre limits: the wall, and the roughing boundary inside it.
    let (xa, xb, ya, yb) = (x0 + r, x0 + w - r, y0 + r, y0 + h - r);
    let (ra, rb, sa, sb) = (
        xa + allowance,
        xb - allowance,
        ya + allowance,
        yb - allowance,
    );
    let levels = (depth / step_down).ceil() as usize;
    // Ramp at 3 degrees: a flat end mill cannot plunge, it enters on a slope.
    let ramp_slope = 3f64.to_radians().tan();
    for level in 1..=levels {
        let z = -(level as f64 * step_down).min(depth);
        // (+ 0.0 turns the first level's -0 into 0.)
        let z_prev = -((level - 1) as f64 * step_down).min(depth) + 0.0;
        lines.push(format!("(level {level}: z {z:.3})"));
        // Ramp backwards onto the first row's start: the row's pass then clears the wedge
        // left under the ramp on its way.
        let ramp_len = ((z_prev - z) / ramp_slope).min(rb - ra);
        lines.push(format!("G0 X{:.4} Y{sa:.4}", ra + ramp_len));
        lines.push(format!("G0 Z{:.4}", z_prev + 0.5));
        lines.push(format!("G1 Z{z_prev:.4} F{:.1}", feed_mm_min * 0.5));
        lines.push(format!("G1 X{ra:.4} Z{z:.4} F{feed_mm_min:.1}"));
        // Zig-zag along x, stepping over in y.
        let rows = ((sb - sa) / stepover).ceil().max(1.0) as usize;
        for row in 0..=rows {
            let y = sa + row as f64 * (sb - sa) / rows as f64;
            lines.push(format!("G1 Y{y:.4}"));
            let x = if row % 2 == 0 { rb } else { ra };
            lines.push(format!("G1 X{x:.4}"));
        }
        // Finishing lap: counter-clockwise inside the pocket, so the wall is on the right
        // of the path: climb milling with a clockwise (M3) spindle.
        lines.push(format!("G1 X{ra:.4} Y{sa:.4}"));
        lines.push(format!("G1 X{xa:.4} Y{ya:.4}"));
        lines.push(format!("G1 X{xb:.4}"));
        lines.push(format!("G1 Y{yb:.4}"));
        lines.push(format!("G1 X{xa:.4}"));
        lines.push(format!("G1 Y{ya:.4}"));
        lines.push("G0 Z5".into());
    }
    lines.push("M5".into());
    lines.push("M30".into());
    let mut s = lines.join("\n");
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const OPTS: GcodeOptions = GcodeOptions {
        start: [0.0, 0.0, 10.0],
        rapid_mm_min: 6000.0,
    };

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
    }

    #[test]
    fn lines_rapids_and_relative_moves() {
        let p = Toolpath::from_gcode(
            "G21 G90 (setup)\nS6000 M3\nG0 X10 Y0 ; comment\nG1 Z0 F600\nG91 X5\nG90 G1 X20 Y5\n",
            "t.nc",
            &OPTS,
        )
        .expect("parses");
        assert_eq!(p.segments.len(), 4);
        let s0 = &p.segments[0];
        assert!(!s0.feed);
        assert!((s0.dur - 10.0 / 6000.0 * 60.0).abs() < 1e-12);
        let s2 = &p.segments[2];
        assert!(close(s2.p0, [10.0, 0.0, 0.0]) && close(s2.p1, [15.0, 0.0, 0.0]));
        assert!((s2.dur - 0.5).abs() < 1e-12);
        assert_eq!(s2.rpm, 6000.0);
        assert_eq!(s2.line, 5);
        let mut cur = 0;
        let pt = p.sample(s2.t0 + 0.25, &mut cur);
        assert!(close(pt.pos, [12.5, 0.0, 0.0]));
        assert!(close(pt.vel, [10.0, 0.0, 0.0]));
    }

    #[test]
    fn arcs_by_centre_and_radius_agree() {
        // Quarter circle clockwise from (10, 0) to (0, -10) about the origin.
        let a = Toolpath::from_gcode("G1 X10 Y0 F600\nG2 X0 Y-10 I-10 J0\n", "a.nc", &OPTS)
            .expect("ij");
        let b = Toolpath::from_gcode("G1 X10 Y0 F600\nG2 X0 Y-10 R10\n", "b.nc", &OPTS).expect("r");
        let (sa, sb) = (a.segments[1], b.segments[1]);
        let (aa, ab) = (sa.arc.expect("arc"), sb.arc.expect("arc"));
        assert!((aa.sweep + PI / 2.0).abs() < 1e-9, "{aa:?}");
        assert!(
            (ab.sweep - aa.sweep).abs() < 1e-9
                && close([ab.centre[0], ab.centre[1], 0.0], [0.0; 3])
        );
        let (mid, vel) = sa.at(0.5);
        let h = 10.0 / 2f64.sqrt();
        assert!(close(mid, [h, -h, 10.0]), "{mid:?}");
        // Clockwise at (h, -h): velocity points to (-1, -1)/sqrt 2.
        assert!(vel[0] < 0.0 && vel[1] < 0.0);
        // Negative R: the major arc, centre on the other side.
        let c = Toolpath::from_gcode("G1 X10 Y0 F600\nG2 X0 Y-10 R-10\n", "c.nc", &OPTS)
            .expect("major");
        let sc = c.segments[1].arc.expect("arc");
        assert!((sc.sweep + 1.5 * PI).abs() < 1e-9, "{sc:?}");
        // Full circle.
        let d = Toolpath::from_gcode("G1 X10 Y0 F600\nG3 I-10\n", "d.nc", &OPTS).expect("full");
        assert!((d.segments[1].arc.expect("arc").sweep - TAU).abs() < 1e-9);
    }

    #[test]
    fn errors_name_file_and_line() {
        let e = |text: &str| {
            format!(
                "{:#}",
                Toolpath::from_gcode(text, "bad.nc", &OPTS).expect_err(text)
            )
        };
        assert!(e("G0 X1\nG20\n").starts_with("bad.nc:2: G20"));
        assert!(e("G1 X5\n").contains("bad.nc:1: feed move with no feed rate"));
        assert!(e("G1 X10 F100\nG2 X0 Y3 I-10\n").contains("bad.nc:2: arc radius differs"));
        assert!(e("M4\n").contains("M4"));
        assert!(e("G1 X1 F100 (open\n").contains("not closed"));
        assert!(e("G81 X1\n").contains("G81 is not supported"));
        assert!(e("G1 X1 Q3 F100\n").contains("word `Q`"));
        assert!(e("G1 X\n").contains("`X` is not followed by a number"));
    }

    #[test]
    fn csv_positions_and_errors() {
        let text = "time_s,x_mm,y_mm,z_mm,spindle_rpm,extra\n0,0,0,0,6000,a\n0.04,1,0,0,6000,b\n0.08,1,2,0,0,c\n";
        let p = Toolpath::from_csv(text, "p.csv").expect("parses");
        assert_eq!(p.segments.len(), 2);
        let mut cur = 0;
        let pt = p.sample(0.06, &mut cur);
        assert!(close(pt.pos, [1.0, 1.0, 0.0]));
        assert!((pt.vel[1] - 50.0).abs() < 1e-9);
        assert_eq!(pt.rpm, 6000.0);
        let bad = "time_s,x_mm,y_mm,z_mm,spindle_rpm\n0,0,0,0,6000\n0,1,0,0,6000\n";
        let e = format!("{:#}", Toolpath::from_csv(bad, "b.csv").expect_err("time"));
        assert!(e.starts_with("b.csv line 3: time_s"), "{e}");
        let bad = "time_s,x_mm,y_mm,z_mm,spindle_rpm\n0,0,zero,0,6000\n";
        let e = format!("{:#}", Toolpath::from_csv(bad, "b.csv").expect_err("num"));
        assert!(e.starts_with("b.csv line 2: y_mm"), "{e}");
        let e = format!(
            "{:#}",
            Toolpath::from_csv("t,x\n0,0\n", "h.csv").expect_err("header")
        );
        assert!(e.contains("no `time_s` column"), "{e}");
    }

    #[test]
    fn pocket_program_parses() {
        let text = pocket_program(
            [0.0, 0.0],
            [60.0, 40.0],
            5.0,
            2.5,
            5.0,
            5.0,
            0.5,
            900.0,
            6000.0,
        );
        let p = Toolpath::from_gcode(&text, "pocket", &OPTS).expect("parses");
        let (len, t) = p.feed_totals();
        assert!(len > 500.0 && t > 60.0, "{len} mm in {t} s");
    }
}
