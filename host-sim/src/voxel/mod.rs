//! `voxel`: milling simulation by material removal on a voxel grid (paper 004;
//! method.md section 6; docs/voxel.md).
//!
//! The analytic simulator needs the engagement given; a pocket, a corner or a ramp changes
//! it continuously, and only a material-removal model knows it. This one follows paper
//! 004: the stock is voxels ([`stock`], stored as z-intervals per column), the tool is a
//! stack of disk elements with one edge point per flute ([`cutter`]), the toolpath is
//! G-code or a CSV of timed positions ([`toolpath`]), and every `1/24` revolution each
//! element removes the voxels its edge swept and turns their count into a chip thickness
//! and a force ([`sim`]). The run is streamed: [`sim::run_path`] hands each step's
//! [`VoxelSample`] to a callback and keeps nothing. [`trace`] resamples the steps to the
//! board's ADC rate and puts them through the analytic simulator's board model
//! ([`crate::sim::chain::Board`]): the same raw trace as `simulate`, for `replay`.
//!
//! # Frames and signs
//! - Machine axes X, Y, Z of the table (right-handed, Z up along the tool axis, away from
//!   the work). Positions are of the tool tip (centre of the end face).
//! - The spindle turns clockwise seen from above (`M3`, right-hand cutter, right-hand
//!   helix). A flute's edge at machine angle `alpha` (counter-clockwise from +X) moves
//!   along `e_t = (sin alpha, -cos alpha)`.
//! - `fx_n, fy_n, fz_n` are the force **on the tool**, in machine axes: the work pushes a
//!   cutting edge back against its motion and outwards from the material,
//!   `F = -dF_t e_t - dF_r e_r - dF_a e_z`, summed over the elements. `torque_nm` is the
//!   load torque on the spindle, `sum dF_t R_j`, positive (it resists the rotation).
//! - The core's [`estimator_core::geometry`] works in the feed frame: x along the feed
//!   direction `f`, y = `f` turned +90 deg (to the left of the path), immersion angle `phi`
//!   clockwise from +y, and its `dF_x = dF_t cos(phi) + dF_r sin(phi)`,
//!   `dF_y = -dF_t sin(phi) + dF_r cos(phi)`, `dF_z = dF_a` are the force **on the work**
//!   (what a table dynamometer reads; `F_ax < 0` in light down milling, "the cutter pulls
//!   the work"). The two are related by a rotation and a sign: with the feed direction at
//!   angle `theta` in the machine frame,
//!
//!   ```text
//!   F_tool(machine) = -Rot(theta) F_work(feed frame),   Rot(theta) = [cos -sin; sin cos]
//!   ```
//!
//!   For a straight cut along +X, `fx_n = -F_ax`, `fy_n = -F_ay`, `fz_n = -F_az`,
//!   `torque_nm = F_at R / 1000`. Down milling along +X has the material on -Y (to the
//!   right of the path), up milling on +Y; tests/voxel_forces.rs checks all of it against
//!   `estimator_core::average_forces_linear`.
//!
//! # CLI
//! `host-sim voxel --stock x0,y0,z0,x1,y1,z1 --toolpath path.nc [--output trace.csv]
//! [--board board.toml] [--steps-csv steps.csv]`; see [`VoxelArgs`] and
//! `host-sim voxel --help`.

pub mod cutter;
pub mod heightmap;
pub mod sim;
pub mod stock;
pub mod toolpath;
pub mod trace;

use crate::trace::TraceWriter;
use anyhow::{anyhow, bail, Context, Result};
use cutter::Cutter;
use serde::Serialize;
use sim::{EdgeRule, SimConfig, Simulator};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;
use stock::Stock;
use toolpath::{GcodeOptions, Toolpath};
use trace::{BoardSpec, TraceSampler};

/// One simulation step (1/`steps_per_rev` of a revolution): the tool's state, the forces,
/// and the engagement measured from the voxels. Signs: see the module doc.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct VoxelSample {
    /// Time at the end of the step [s].
    pub time_s: f64,
    /// Tool tip X [mm].
    pub x_mm: f64,
    /// Tool tip Y [mm].
    pub y_mm: f64,
    /// Tool tip Z [mm].
    pub z_mm: f64,
    /// Feed velocity X [mm/min].
    pub feed_vx_mm_min: f64,
    /// Feed velocity Y [mm/min].
    pub feed_vy_mm_min: f64,
    /// Spindle speed [rpm].
    pub spindle_rpm: f64,
    /// Spindle rotation since the start at the end of the step [rad] (unwrapped,
    /// increasing): flute `j`'s tip is at machine angle `-angle - j 2pi/N`.
    pub spindle_angle_rad: f64,
    /// True on the step in which a flute passes the reference angle: once per tooth period.
    pub tooth_sync: bool,
    /// Force on the tool along machine X [N], averaged over the step.
    pub fx_n: f64,
    /// Force on the tool along machine Y [N].
    pub fy_n: f64,
    /// Force on the tool along machine Z [N].
    pub fz_n: f64,
    /// Spindle load torque [N m].
    pub torque_nm: f64,
    /// Radial depth of cut measured from the voxels at the last `tooth_sync` [mm]; NaN
    /// while the tool does not move in XY.
    pub true_dr_mm: f64,
    /// Axial depth of cut (height span removed in the last tooth period) [mm].
    pub true_da_mm: f64,
    /// Material removal rate of the step [mm^3/s].
    pub mrr_mm3_s: f64,
    /// Bit `j` set while flute `j` is intact (breakage is not simulated yet: all set).
    pub flutes_intact: u8,
}

/// The CSV header of `--steps-csv`: the field names of [`VoxelSample`], in order.
pub const CSV_HEADER: &str = "time_s,x_mm,y_mm,z_mm,feed_vx_mm_min,feed_vy_mm_min,spindle_rpm,\
spindle_angle_rad,tooth_sync,fx_n,fy_n,fz_n,torque_nm,true_dr_mm,true_da_mm,mrr_mm3_s,flutes_intact";

impl VoxelSample {
    /// Writes the sample as one CSV line (`tooth_sync` as 1/0).
    pub fn write_csv(&self, w: &mut impl Write) -> std::io::Result<()> {
        // Formatting dominates a run with output (std's `{:.4}` costs more than a
        // simulation step), hence the fixed-point writer.
        let mut b = Vec::with_capacity(192);
        for (v, decimals) in [
            (self.time_s, 6),
            (self.x_mm, 4),
            (self.y_mm, 4),
            (self.z_mm, 4),
            (self.feed_vx_mm_min, 2),
            (self.feed_vy_mm_min, 2),
            (self.spindle_rpm, 1),
            (self.spindle_angle_rad, 6),
        ] {
            push_fixed(&mut b, v, decimals);
            b.push(b',');
        }
        b.extend_from_slice(if self.tooth_sync { b"1," } else { b"0," });
        for (v, decimals) in [
            (self.fx_n, 3),
            (self.fy_n, 3),
            (self.fz_n, 3),
            (self.torque_nm, 5),
            (self.true_dr_mm, 3),
            (self.true_da_mm, 3),
            (self.mrr_mm3_s, 2),
        ] {
            push_fixed(&mut b, v, decimals);
            b.push(b',');
        }
        push_uint(&mut b, u64::from(self.flutes_intact));
        b.push(b'\n');
        w.write_all(&b)
    }
}

/// Appends `v` with `decimals` digits after the point, as `format!("{v:.decimals$}")`
/// does (but for ties, and `0.000` where std writes `-0.000`).
fn push_fixed(out: &mut Vec<u8>, v: f64, decimals: u32) {
    let scale = 10f64.powi(decimals as i32);
    let scaled = (v * scale).round();
    if !scaled.is_finite() || scaled.abs() >= 9e15 {
        // NaN, inf, or beyond exact integers: std's formatting.
        out.extend_from_slice(format!("{v:.*}", decimals as usize).as_bytes());
        return;
    }
    let mut n = scaled as i64;
    if n < 0 {
        out.push(b'-');
        n = -n;
    }
    let n = n as u64;
    let p = 10u64.pow(decimals);
    push_uint(out, n / p);
    if decimals > 0 {
        out.push(b'.');
        let frac = n % p;
        let mut digits = [b'0'; 20];
        let mut f = frac;
        for d in digits[..decimals as usize].iter_mut().rev() {
            *d = b'0' + (f % 10) as u8;
            f /= 10;
        }
        out.extend_from_slice(&digits[..decimals as usize]);
    }
}

/// Appends `n` in decimal.
fn push_uint(out: &mut Vec<u8>, mut n: u64) {
    let mut digits = [0u8; 20];
    let mut i = digits.len();
    loop {
        i -= 1;
        digits[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.extend_from_slice(&digits[i..]);
}

const VOXEL_HELP: &str = "\
MODEL (paper 004): the stock is a block of voxels; the tool is a stack of disk elements
with one edge point per flute, lagging along the helix. Each step (1/24 rev by default)
every element removes the voxels its edge swept; n removed voxels of size m give the chip
thickness h = n m^3 / (d dz) (d: edge travel, dz: disk thickness) and the forces
  dF_t = K_tc h dz + K_te dz,  dF_r = K_rc h dz + K_re dz,  dF_a = K_ac h dz + K_ae dz
(edge terms only where material was removed), summed in machine axes.

TOOLPATH: G-code in mm (G0 G1 G2 G3 with I/J or R, G4 P<s>, G90/G91, F mm/min, S rpm,
M3/M5), or a CSV (name ending .csv) of timed tool-tip positions as a CNC streams them:
  time_s,x_mm,y_mm,z_mm,spindle_rpm      (linearly interpolated between rows)

TRACE (--output): the raw trace of `host-sim simulate` (docs/formats.md), for `replay`: the
steps resampled to --sample-rate-hz (each sample holds the force of the step it falls in)
and put through the board of --board (a TOML with optional `input`, `signal`, `sync` and
`seed`, shaped as in a simulate scenario, host-sim/examples/cut.toml; default: the
monitor's default one-axis motor input, ideal signal chain, a sync pulse per tooth):
  time_s, sync, feed_x_a [feed_y_a] | fx_n fy_n, feed_vx_mm_min [feed_vy_mm_min],
  spindle_a | spindle_load_pct, true_dr_mm, true_da_mm (from the voxels), true_tc_mm,
  true_rpm, true_flutes_intact, true_fx_n, true_fy_n, true_ft_n (F_ax, F_ay, F_at: feed
  frame, force ON THE WORK, F_ax > 0 resisting the feed, as method.md eq. 7)
Replay it with a config of the same input, tool and sample rate.

STEPS (--steps-csv, CSV, one row per simulation step):
  time_s, x_mm, y_mm, z_mm          tool tip at the end of the step
  feed_vx_mm_min, feed_vy_mm_min    feed velocity
  spindle_rpm
  spindle_angle_rad                 spindle rotation since the start (flute 0's tip at
                                    machine angle -spindle_angle_rad)
  tooth_sync                        1 on the step a flute passes the reference angle
  fx_n, fy_n, fz_n                  force ON THE TOOL in machine axes [N]
  torque_nm                         spindle load torque [N m]
  true_dr_mm, true_da_mm            radial/axial depth of cut measured from the voxels,
                                    updated at each tooth_sync (dr NaN without XY motion)
  mrr_mm3_s                         material removal rate
  flutes_intact                     bitmask of intact flutes
A straight cut along +X: fx_n = -F_ax, fy_n = -F_ay of method.md eq. 7 (which gives the
force on the work); down milling has the material on -Y. See docs/voxel.md.

TOOL FILE (TOML, every key optional):
  radius_mm = 5.0
  flutes = 3
  helix_deg = 30.0
  length_mm = 20.0               # flute length: material above it is not cut
  runout_mm = [0.01, 0.0, 0.0]   # radial offset of each flute's edge
MATERIAL FILE (TOML, all keys): ktc, krc, kac [N/mm^2], kte, kre, kae [N/mm]

EXAMPLE:
  host-sim voxel --stock 0,0,-20,70,50,0 --tool radius=5,flutes=3,helix=30 \\
      --toolpath host-sim/tests/data/pocket_60x40.nc --output trace.csv --heightmap top.png";

/// `host-sim voxel`: simulate milling a block along a toolpath by voxel material removal.
#[derive(clap::Args, Debug, Clone)]
#[command(after_help = VOXEL_HELP)]
pub struct VoxelArgs {
    /// Stock block: two opposite corners "x0,y0,z0,x1,y1,z1" [mm].
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", allow_hyphen_values = true)]
    pub stock: String,
    /// Voxel edge [mm] (paper: 0.09).
    #[arg(long, default_value_t = 0.09, value_name = "MM")]
    pub voxel_mm: f64,
    /// Flat end mill: "radius=5,flutes=3,helix=30,length=20[,runout=0.01/0/0]" (mm, deg;
    /// `diameter=` also accepted) or a TOML file (see below).
    #[arg(
        long,
        default_value = "radius=5,flutes=3,helix=30,length=20",
        value_name = "SPEC|FILE"
    )]
    pub tool: String,
    /// Work material: `al6061` (paper 004's coefficients) or a TOML file of the six
    /// coefficients.
    #[arg(long, default_value = "al6061", value_name = "NAME|FILE")]
    pub material: String,
    /// Toolpath: G-code (mm), or CSV of timed positions if the name ends in `.csv`.
    #[arg(long, value_name = "FILE")]
    pub toolpath: PathBuf,
    /// Write the raw trace here (`-`: standard output): the format of `simulate`, through
    /// the board of `--board`, for `replay`.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// ADC sample rate of the trace [Hz].
    #[arg(long, default_value_t = 20000.0, value_name = "HZ")]
    pub sample_rate_hz: f64,
    /// The board (TOML: optional `input`, `signal`, `sync`, `seed` tables/keys of a simulate
    /// scenario); default: the monitor's default input, an ideal signal chain.
    #[arg(long, value_name = "FILE")]
    pub board: Option<PathBuf>,
    /// Write one CSV row per simulation step here (`-`: standard output): forces on the
    /// tool in machine axes, the measured engagement, the material removal rate.
    #[arg(long, value_name = "FILE")]
    pub steps_csv: Option<PathBuf>,
    /// Time steps per spindle revolution (paper: 24).
    #[arg(long, default_value_t = 24, value_name = "N")]
    pub steps_per_rev: u32,
    /// Disk element thickness [mm] (paper: 0.6).
    #[arg(long, default_value_t = 0.6, value_name = "MM")]
    pub disk_mm: f64,
    /// G0 rate [mm/min].
    #[arg(long, default_value_t = 10000.0, value_name = "MM_MIN")]
    pub rapid_mm_min: f64,
    /// Tool tip before the first G-code move "x,y,z" [mm]; default 0, 0 and 10 mm above
    /// the stock.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub start: Option<String>,
    /// Write the final stock's height map here (16-bit grey PNG, one pixel per column).
    #[arg(long, value_name = "FILE")]
    pub heightmap: Option<PathBuf>,
    /// Edge-force contact rule: `span` (contact from the angular span of the removed
    /// voxels) or `any` (paper 004: the whole step once anything is removed).
    #[arg(long, default_value = "span", value_name = "RULE")]
    pub edge_rule: String,
    /// Print the speed (simulated machining seconds per wall second) and counters.
    #[arg(long)]
    pub bench: bool,
}

/// Parses `n` comma-separated numbers named `what`.
fn parse_numbers<const N: usize>(text: &str, what: &str) -> Result<[f64; N]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| anyhow!("{what}: `{}` is not a number", s.trim()))
        })
        .collect::<Result<_>>()?;
    v.try_into()
        .map_err(|v: Vec<f64>| anyhow!("{what}: expected {N} numbers, got {}", v.len()))
}

/// Parses `--stock` into its minimum and maximum corners.
pub fn parse_stock(text: &str) -> Result<([f64; 3], [f64; 3])> {
    let v: [f64; 6] = parse_numbers(text, "--stock")?;
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for a in 0..3 {
        lo[a] = v[a].min(v[a + 3]);
        hi[a] = v[a].max(v[a + 3]);
    }
    Ok((lo, hi))
}

/// Parses `--edge-rule`.
pub fn parse_edge_rule(text: &str) -> Result<EdgeRule> {
    match text {
        "span" => Ok(EdgeRule::Span),
        "any" => Ok(EdgeRule::AnyRemoval),
        other => bail!("--edge-rule: `{other}` is neither `span` nor `any`"),
    }
}

impl Default for VoxelArgs {
    /// The command's defaults, with no stock (`""`) and no toolpath: set those.
    fn default() -> Self {
        VoxelArgs {
            stock: String::new(),
            voxel_mm: 0.09,
            tool: "radius=5,flutes=3,helix=30,length=20".into(),
            material: "al6061".into(),
            toolpath: PathBuf::new(),
            output: None,
            sample_rate_hz: 20000.0,
            board: None,
            steps_csv: None,
            steps_per_rev: 24,
            disk_mm: 0.6,
            rapid_mm_min: 10000.0,
            start: None,
            heightmap: None,
            edge_rule: "span".into(),
            bench: false,
        }
    }
}

/// An output file written beside its name and renamed into place only by
/// [`Output::commit`], so a failed run never leaves a truncated file that looks complete;
/// `-` is standard output.
struct Output {
    w: BufWriter<Box<dyn Write>>,
    name: String,
    /// `(temporary, final)` paths of a file not yet committed.
    rename: Option<(PathBuf, PathBuf)>,
}

impl Output {
    fn create(path: &Path) -> Result<Output> {
        if path == Path::new("-") {
            return Ok(Output {
                w: BufWriter::with_capacity(1 << 16, Box::new(std::io::stdout())),
                name: "standard output".into(),
                rename: None,
            });
        }
        let mut tmp_name = path.as_os_str().to_owned();
        tmp_name.push(".partial");
        let tmp = PathBuf::from(tmp_name);
        let f = File::create(&tmp).with_context(|| format!("cannot create {}", tmp.display()))?;
        Ok(Output {
            w: BufWriter::with_capacity(1 << 16, Box::new(f)),
            name: path.display().to_string(),
            rename: Some((tmp, path.to_path_buf())),
        })
    }

    fn commit(mut self) -> Result<()> {
        self.w
            .flush()
            .with_context(|| format!("cannot write {}", self.name))?;
        if let Some((tmp, path)) = self.rename.take() {
            std::fs::rename(&tmp, &path).with_context(|| {
                format!("cannot rename {} to {}", tmp.display(), path.display())
            })?;
        }
        Ok(())
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.w.write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.w.write_all(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.w.flush()
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Some((tmp, _)) = &self.rename {
            // Best effort: the error being reported matters more than a leftover file.
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Runs `host-sim voxel`.
pub fn run(args: &VoxelArgs) -> Result<()> {
    let (lo, hi) = parse_stock(&args.stock)?;
    let cutter = Cutter::parse(&args.tool)?;
    let coeffs = cutter::parse_material(&args.material)?;
    let cfg = SimConfig {
        cutter: cutter.clone(),
        coeffs,
        steps_per_rev: args.steps_per_rev,
        disk_mm: args.disk_mm,
        edge: parse_edge_rule(&args.edge_rule)?,
        skip_cleared: true,
    };
    cfg.validate()?;
    let start = match &args.start {
        Some(s) => parse_numbers::<3>(s, "--start")?,
        None => [0.0, 0.0, hi[2] + 10.0],
    };
    let path = Toolpath::load(
        &args.toolpath,
        &GcodeOptions {
            start,
            rapid_mm_min: args.rapid_mm_min,
        },
    )?;
    let board = match &args.board {
        Some(p) => BoardSpec::load(p)?,
        None => BoardSpec::default(),
    };
    let max_rpm = path.segments.iter().map(|s| s.rpm).fold(0.0, f64::max);
    board
        .validate(&cutter, args.sample_rate_hz, max_rpm)
        .map_err(|e| match &args.board {
            Some(p) => anyhow!("{}: {e:#}", p.display()),
            None => e,
        })?;
    if let (Some(a), Some(b)) = (&args.output, &args.steps_csv) {
        if a == b {
            bail!(
                "--output and --steps-csv both name {}: give them different files",
                a.display()
            );
        }
    }
    // Feed moves with the spindle stopped cut nothing (the model needs the rotation):
    // usually a missing S word, so say so rather than write a trace of zeros.
    let idle: Vec<_> = path
        .segments
        .iter()
        .filter(|s| s.feed && s.rpm <= 0.0)
        .collect();
    if let Some(first) = idle.first() {
        eprintln!(
            "warning: {}: {:.1} s of feed moves with the spindle stopped (from line {}: no S \
             word yet, or after M5); nothing is cut during them",
            args.toolpath.display(),
            idle.iter().map(|s| s.dur).sum::<f64>(),
            first.line
        );
    }
    if args.output.is_some() {
        let moves_y = path
            .segments
            .iter()
            .any(|s| s.feed && (s.arc.is_some() || (s.p1[1] - s.p0[1]).abs() > 1e-9));
        if let Some(w) = trace::one_axis_warning(&board, moves_y) {
            eprintln!("warning: {w}");
        }
    }
    let stock = Stock::block(lo, hi, args.voxel_mm)?;
    let [nx, ny, nz] = stock.dims();
    let mem_mb = stock.memory_bytes() as f64 / 1048576.0;
    let mut sim = Simulator::new(cfg, stock)?;

    let mut trace_out = args.output.as_deref().map(Output::create).transpose()?;
    let mut steps_out = args.steps_csv.as_deref().map(Output::create).transpose()?;
    let trace_name = trace_out
        .as_ref()
        .map(|o| o.name.clone())
        .unwrap_or_default();
    let steps_name = steps_out
        .as_ref()
        .map(|o| o.name.clone())
        .unwrap_or_default();
    let mut tw = match trace_out.as_mut() {
        Some(o) => Some(
            TraceWriter::new(o, board.trace_kind(), args.sample_rate_hz)
                .with_context(|| format!("cannot write {trace_name}"))?,
        ),
        None => None,
    };
    let mut sampler = tw
        .is_some()
        .then(|| TraceSampler::new(&board, &cutter, args.sample_rate_hz, path.t_start));
    if let Some(o) = steps_out.as_mut() {
        writeln!(o, "{CSV_HEADER}").with_context(|| format!("cannot write {steps_name}"))?;
    }
    let t_wall = Instant::now();
    let stats = sim::run_path(&mut sim, &path, |s| {
        if let Some(o) = steps_out.as_mut() {
            s.write_csv(o)
                .with_context(|| format!("cannot write {steps_name}"))?;
        }
        if let (Some(sm), Some(w)) = (sampler.as_mut(), tw.as_mut()) {
            sm.step(s, |row| w.write_row(row))
                .with_context(|| format!("cannot write {trace_name}"))?;
        }
        Ok(())
    })?;
    if let Some(w) = tw {
        w.finish()
            .with_context(|| format!("cannot write {trace_name}"))?;
    }
    for o in [trace_out, steps_out].into_iter().flatten() {
        o.commit()?;
    }
    let wall = t_wall.elapsed().as_secs_f64();
    if let Some(p) = &args.heightmap {
        heightmap::write_png(sim.stock(), p)?;
    }
    let (feed_len, feed_s) = path.feed_totals();
    let m = args.voxel_mm;
    let (disks, dz) = sim.disks();
    let removed_mm3 = stats.removed_voxels as f64 * m * m * m;
    let mut summary = format!(
        "{}: {:.1} s simulated ({:.1} s of feed moves, {:.0} mm; {:.1} s cutting) \
         in {:.2} s wall: {:.1}x real time\n  {} steps, {} x {} x {} voxels of {} mm ({:.0} MB), \
         {} disks of {:.3} mm, {:.0} mm^3 removed (MRR {:.0} mm^3/s while cutting), {:.0} columns visited per step, {} full-wedge \
         element scans",
        args.toolpath.display(),
        stats.sim_s,
        feed_s,
        feed_len,
        stats.cutting_s,
        wall,
        stats.sim_s / wall.max(1e-9),
        stats.steps,
        nx,
        ny,
        nz,
        m,
        mem_mb,
        disks,
        dz,
        removed_mm3,
        removed_mm3 / stats.cutting_s.max(1e-9),
        stats.column_visits as f64 / stats.steps.max(1) as f64,
        stats.full_scans,
    );
    if let Some(sm) = &sampler {
        let t = sm.summary();
        summary += &format!(
            "\n  trace {trace_name}: {} rows at {} Hz, {} sync pulses ({} dropped), clipped \
             samples {:?} (clip levels {:?})",
            t.rows, t.sample_rate_hz, t.sync_pulses, t.sync_dropped, t.clipped, t.clip_levels
        );
    }
    if args.bench {
        println!("{summary}");
    } else {
        eprintln!("{summary}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_header_names_every_field_in_order() {
        // serde gives the field names in declaration order.
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(VoxelSample::default()).expect("serialise");
        let text = String::from_utf8(w.into_inner().expect("flush")).expect("utf8");
        assert_eq!(text.lines().next(), Some(CSV_HEADER));
        let mut line = Vec::new();
        VoxelSample::default().write_csv(&mut line).expect("write");
        let fields = String::from_utf8(line).expect("utf8");
        assert_eq!(
            fields.trim().split(',').count(),
            CSV_HEADER.split(',').count()
        );
    }

    #[test]
    fn fixed_point_matches_std() {
        let mut x = 0.123_456_789f64;
        for i in 0..2000 {
            // A spread of magnitudes and signs, avoiding exact ties.
            x = (x * 7.3 + 0.011 * i as f64) % 1.0;
            let v = (x - 0.5) * 10f64.powi(i % 9 - 2);
            for d in [0u32, 1, 3, 6] {
                let mut b = Vec::new();
                push_fixed(&mut b, v, d);
                let std = format!("{v:.*}", d as usize);
                let std = std
                    .strip_prefix('-')
                    .filter(|s| s.bytes().all(|c| c == b'0' || c == b'.'))
                    .map_or(std.clone(), str::to_string);
                assert_eq!(
                    String::from_utf8(b).expect("utf8"),
                    std,
                    "{v} with {d} decimals"
                );
            }
        }
        let mut b = Vec::new();
        push_fixed(&mut b, f64::NAN, 3);
        assert_eq!(b, b"NaN");
    }

    #[test]
    fn stock_and_numbers() {
        let (lo, hi) = parse_stock("10,0,-5, 0,20,0").expect("parses");
        assert_eq!(lo, [0.0, 0.0, -5.0]);
        assert_eq!(hi, [10.0, 20.0, 0.0]);
        let e = format!("{:#}", parse_stock("1,2,3").expect_err("short"));
        assert!(e.contains("expected 6 numbers, got 3"), "{e}");
        let e = format!("{:#}", parse_stock("1,2,x,4,5,6").expect_err("text"));
        assert!(e.contains("`x` is not a number"), "{e}");
    }
}
