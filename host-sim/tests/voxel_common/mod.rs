//! Shared harness of the voxel tests: a straight cut at constant engagement, averaged over
//! whole tooth periods in its steady part.

#![allow(dead_code)]

use estimator_core::coefficients::{LinearCoefficients, AL6061};
use estimator_core::{average_forces_linear, AverageForces, Engagement, MillingMode};
use host_sim::voxel::cutter::Cutter;
use host_sim::voxel::sim::{run_path, EdgeRule, RunStats, SimConfig, Simulator};
use host_sim::voxel::stock::Stock;
use host_sim::voxel::toolpath::{GcodeOptions, Toolpath};
use host_sim::voxel::VoxelSample;

/// Which way the straight cut feeds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feed {
    PlusX,
    PlusY,
}

/// A straight cut: the tool (R 5 mm, 3 flutes, 30 deg helix) enters a block from outside
/// and feeds through it with radial depth `dr` on the side `mode` puts the material
/// (down milling: right of the path), axial depth `da`.
#[derive(Clone, Copy, Debug)]
pub struct Cut {
    pub mode: MillingMode,
    pub dr: f64,
    pub da: f64,
    pub tc: f64,
    pub voxel: f64,
    pub edge: EdgeRule,
    pub feed: Feed,
    pub helix: f64,
    pub skip_cleared: bool,
    /// Work material (default Al6061).
    pub coeffs: LinearCoefficients,
    /// Length of the block along the feed [mm] (default 14).
    pub stock_len: f64,
    /// Where the tool centre stops along the feed [mm] (default 8, inside the block).
    pub end: f64,
}

impl Cut {
    pub fn new(mode: MillingMode, dr: f64, da: f64, tc: f64, voxel: f64) -> Cut {
        Cut {
            mode,
            dr,
            da,
            tc,
            voxel,
            edge: EdgeRule::Span,
            feed: Feed::PlusX,
            helix: 30.0,
            skip_cleared: true,
            coeffs: AL6061,
            stock_len: STOCK_LEN,
            end: END,
        }
    }
}

pub const R: f64 = 5.0;
pub const FLUTES: u8 = 3;
pub const RPM: f64 = 6000.0;
/// Steady part of the cut: tool centre between these distances along the feed [mm].
pub const WINDOW: (f64, f64) = (1.0, 7.0);
const STOCK_LEN: f64 = 14.0;
const END: f64 = 8.0;

/// Per-tooth-period averages of a run, in machine axes, force on the tool.
#[derive(Debug, Default)]
pub struct CutResult {
    pub fx: f64,
    pub fy: f64,
    pub fz: f64,
    pub torque_nm: f64,
    pub teeth: usize,
    pub dr_meas: Vec<f64>,
    pub da_meas: Vec<f64>,
    pub stats: RunStats,
    pub removed_voxels: u64,
    pub samples: Vec<VoxelSample>,
}

/// The programmed cut's forces from the core (eq. 7, linear model), force on the work in
/// the feed frame.
pub fn analytic(c: &Cut) -> AverageForces {
    let tool = estimator_core::Tool {
        radius_mm: R as f32,
        flutes: FLUTES,
        helix_deg: c.helix as f32,
    };
    average_forces_linear(
        &tool,
        &c.coeffs,
        c.mode,
        Engagement {
            rr: (c.dr / R) as f32,
            ra: (c.da / R) as f32,
            tc_mm: c.tc as f32,
        },
    )
}

/// `[lo, hi]` of length `>= len` ending (`from_hi`) or starting exactly at `face`, in
/// whole voxels.
fn span(face: f64, len: f64, m: f64, from_hi: bool) -> (f64, f64) {
    let n = (len / m).ceil();
    if from_hi {
        (face - n * m, face)
    } else {
        (face, face + n * m)
    }
}

/// Builds the simulator and the path of a straight cut.
pub fn setup(c: &Cut) -> (Simulator, Toolpath) {
    let m = c.voxel;
    // Across the feed, in the feed frame's y (left of the path): down milling has the
    // material on the right (negative y), up milling on the left.
    let slot = c.dr >= 2.0 * R - 1e-9;
    let (ylo, yhi) = if slot {
        span(-R - 2.0, 2.0 * R + 4.0, m, false)
    } else {
        match c.mode {
            MillingMode::Down => span(-R + c.dr, c.dr + 2.0, m, true),
            MillingMode::Up => span(R - c.dr, c.dr + 2.0, m, false),
        }
    };
    let (zlo, zhi) = span(0.0, c.da + 1.0, m, true);
    let (alo, ahi) = span(0.0, c.stock_len, m, false);
    let end = c.end;
    // Feed frame -> machine: +X feed: (a, y); +Y feed: left of +Y is -X, so x = -y.
    let (lo, hi, start, target) = match c.feed {
        Feed::PlusX => (
            [alo, ylo, zlo],
            [ahi, yhi, zhi],
            [-R - 0.5, 0.0, -c.da],
            format!("X{end}"),
        ),
        Feed::PlusY => (
            [-yhi, alo, zlo],
            [-ylo, ahi, zhi],
            [0.0, -R - 0.5, -c.da],
            format!("Y{end}"),
        ),
    };
    let stock = Stock::block(lo, hi, m).expect("stock");
    let cutter = Cutter {
        radius_mm: R,
        flutes: FLUTES,
        helix_deg: c.helix,
        length_mm: 10.0,
        runout_mm: vec![0.0; FLUTES as usize],
    };
    let cfg = SimConfig {
        cutter,
        coeffs: c.coeffs,
        steps_per_rev: 24,
        disk_mm: 0.6,
        edge: c.edge,
        skip_cleared: c.skip_cleared,
    };
    let sim = Simulator::new(cfg, stock).expect("simulator");
    let feed = c.tc * f64::from(FLUTES) * RPM;
    let text = format!("S{RPM} M3\nG1 {target} F{feed}\n");
    let path = Toolpath::from_gcode(
        &text,
        "cut.nc",
        &GcodeOptions {
            start,
            rapid_mm_min: 10000.0,
        },
    )
    .expect("path");
    (sim, path)
}

/// Runs the cut and averages whole tooth periods inside `WINDOW`.
pub fn run(c: &Cut, keep_samples: bool) -> (CutResult, Simulator) {
    let (mut sim, path) = setup(c);
    let mut res = CutResult::default();
    let mut cur = [0.0f64; 4];
    let mut cur_n = 0usize;
    let mut cur_start = f64::NEG_INFINITY;
    let mut steps = 0usize;
    let along = |s: &VoxelSample| match c.feed {
        Feed::PlusX => s.x_mm,
        Feed::PlusY => s.y_mm,
    };
    let stats = run_path(&mut sim, &path, |s| {
        if keep_samples {
            res.samples.push(*s);
        }
        cur[0] += s.fx_n;
        cur[1] += s.fy_n;
        cur[2] += s.fz_n;
        cur[3] += s.torque_nm;
        cur_n += 1;
        if s.tooth_sync {
            let a = along(s);
            if cur_start >= WINDOW.0 && a <= WINDOW.1 {
                res.fx += cur[0];
                res.fy += cur[1];
                res.fz += cur[2];
                res.torque_nm += cur[3];
                steps += cur_n;
                res.teeth += 1;
                res.dr_meas.push(s.true_dr_mm);
                res.da_meas.push(s.true_da_mm);
            }
            cur = [0.0; 4];
            cur_n = 0;
            cur_start = a;
        }
        Ok(())
    })
    .expect("run");
    let n = steps.max(1) as f64;
    res.fx /= n;
    res.fy /= n;
    res.fz /= n;
    res.torque_nm /= n;
    res.stats = stats;
    res.removed_voxels = stats.removed_voxels;
    (res, sim)
}

/// The simulated averages turned into the core's frame (force on the work, feed frame):
/// `F_work(feed) = -Rot(-theta) F_tool(machine)`.
pub fn to_feed_frame(c: &Cut, r: &CutResult) -> [f64; 4] {
    let (fx, fy) = match c.feed {
        Feed::PlusX => (-r.fx, -r.fy),
        // theta = 90 deg: feed-frame x = machine y, feed-frame y = -machine x.
        Feed::PlusY => (-r.fy, r.fx),
    };
    [fx, fy, -r.fz, r.torque_nm * 1e3 / R]
}

/// Worst error of the four averages against eq. 7, each relative to `|F_at|` (components
/// pass through zero; the tangential force does not), and the individual errors.
pub fn errors(c: &Cut, r: &CutResult) -> (f64, [f64; 4]) {
    let a = analytic(c);
    let sim = to_feed_frame(c, r);
    let want = [a.fx_n, a.fy_n, a.fz_n, a.ft_n].map(f64::from);
    let scale = want[3].abs();
    let mut e = [0.0; 4];
    for i in 0..4 {
        e[i] = (sim[i] - want[i]) / scale;
    }
    (e.iter().fold(0.0f64, |w, x| w.max(x.abs())), e)
}
