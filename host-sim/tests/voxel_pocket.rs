//! The voxel simulator on whole programs: a pocket cleared level by level, against the
//! volume and floor it must leave; the committed benchmark program against its generator;
//! and (ignored) the speed benchmark of BENCHMARKS.md.

use estimator_core::coefficients::AL6061;
use host_sim::voxel::cutter::Cutter;
use host_sim::voxel::sim::{run_path, EdgeRule, SimConfig, Simulator};
use host_sim::voxel::stock::Stock;
use host_sim::voxel::toolpath::{pocket_program, GcodeOptions, Toolpath};
use std::path::Path;
use std::time::Instant;

/// The benchmark program: 60 x 40 x 10 mm pocket in a 70 x 50 x 20 block, 10 mm 3-flute
/// end mill, 4 levels of 2.5 mm, 50 % stepover, 0.5 mm finishing allowance, 6000 rpm,
/// 0.05 mm/tooth (900 mm/min).
fn bench_program() -> String {
    pocket_program(
        [5.0, 5.0],
        [60.0, 40.0],
        10.0,
        2.5,
        5.0,
        5.0,
        0.5,
        900.0,
        6000.0,
    )
}

const BENCH_FILE: &str = "tests/data/pocket_60x40.nc";

fn sim(stock: ([f64; 3], [f64; 3]), voxel: f64) -> Simulator {
    let stock = Stock::block(stock.0, stock.1, voxel).expect("stock");
    let cfg = SimConfig {
        cutter: Cutter::default(),
        coeffs: AL6061,
        steps_per_rev: 24,
        disk_mm: 0.6,
        edge: EdgeRule::Span,
        skip_cleared: true,
    };
    Simulator::new(cfg, stock).expect("simulator")
}

fn opts(top: f64) -> GcodeOptions {
    GcodeOptions {
        start: [0.0, 0.0, top + 10.0],
        rapid_mm_min: 10000.0,
    }
}

#[test]
fn committed_pocket_program_is_the_generated_one() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(BENCH_FILE);
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    if on_disk != bench_program() {
        if std::env::var_os("VOXEL_WRITE_POCKET").is_some() {
            std::fs::write(&path, bench_program()).expect("write");
        } else {
            panic!(
                "{} differs from pocket_program(); rerun with VOXEL_WRITE_POCKET=1 to rewrite it",
                path.display()
            );
        }
    }
}

/// A small pocket (20 x 16 x 3 mm, 2 levels) at 0.15 mm voxels: the volume removed and
/// the floor left are the programmed ones, nothing outside the pocket is touched, and the
/// forces stay finite and plausible throughout.
#[test]
fn small_pocket_volume_and_floor() {
    let (w, h, depth, r) = (20.0, 16.0, 3.0, 5.0);
    let text = pocket_program([5.0, 5.0], [w, h], depth, 1.5, r, 5.0, 0.5, 900.0, 6000.0);
    let path = Toolpath::from_gcode(&text, "small.nc", &opts(0.0)).expect("program");
    let m = 0.15;
    let mut s = sim(([0.0, 0.0, -6.0], [30.0, 27.0, 0.0]), m);
    let before = s.stock().count_voxels();
    let mut worst = 0.0f64;
    let mut samples = 0u64;
    run_path(&mut s, &path, |v| {
        assert!(v.fx_n.is_finite() && v.fy_n.is_finite() && v.fz_n.is_finite());
        worst = worst.max(v.fx_n.hypot(v.fy_n));
        samples += 1;
        Ok(())
    })
    .expect("run");
    let removed = (before - s.stock().count_voxels()) as f64 * m * m * m;
    // A rectangle with corners rounded to the tool radius.
    let want = (w * h - (4.0 - std::f64::consts::PI) * r * r) * depth;
    assert!(
        (removed - want).abs() < 0.02 * want,
        "removed {removed:.1} mm^3, pocket {want:.1}"
    );
    assert!(
        worst > 20.0 && worst < 2000.0,
        "largest XY force {worst:.1} N"
    );
    // Floor at -3 mm inside the pocket (away from the rounded corners), top at 0 outside.
    let o = s.stock().origin();
    let [nx, ny, nz] = s.stock().dims();
    let z_of = |k: u16| o[2] + f64::from(k) * m;
    for iy in 0..ny {
        for ix in 0..nx {
            let x = o[0] + (ix as f64 + 0.5) * m;
            let y = o[1] + (iy as f64 + 0.5) * m;
            let top = z_of(s.stock().top(ix, iy));
            let inside = x > 5.0 + m && x < 5.0 + w - m && y > 5.0 + r && y < 5.0 + h - r;
            let outside = x < 5.0 - m || x > 5.0 + w + m || y < 5.0 - m || y > 5.0 + h + m;
            if inside {
                assert!((top + depth).abs() < m, "floor {top} at ({x:.2}, {y:.2})");
            }
            if outside {
                assert_eq!(
                    s.stock().top(ix, iy) as usize,
                    nz,
                    "cut outside at ({x}, {y})"
                );
            }
        }
    }
    assert!(samples > 10_000);
}

/// Speed on the benchmark program (BENCHMARKS.md). Run in release:
/// `cargo test --release -p host-sim --test voxel_pocket -- --ignored --nocapture`.
#[test]
#[ignore]
fn pocket_speed() {
    let text = bench_program();
    for (name, stock) in [
        (
            "70 x 50 x 20 mm block",
            ([0.0, 0.0, -20.0], [70.0, 50.0, 0.0]),
        ),
        (
            "200 x 150 x 50 mm block",
            ([-65.0, -50.0, -50.0], [135.0, 100.0, 0.0]),
        ),
    ] {
        let path = Toolpath::from_gcode(&text, BENCH_FILE, &opts(stock.1[2])).expect("program");
        let mut s = sim(stock, 0.09);
        let t = Instant::now();
        let stats = run_path(&mut s, &path, |_| Ok(())).expect("run");
        let wall = t.elapsed().as_secs_f64();
        println!(
            "{name}: {:.1} s simulated ({:.1} s cutting) in {wall:.2} s: {:.1}x real \
             time, {:.0} columns/step, {} steps, {:.0} MB",
            stats.sim_s,
            stats.cutting_s,
            stats.sim_s / wall,
            stats.column_visits as f64 / stats.steps as f64,
            stats.steps,
            s.stock().memory_bytes() as f64 / 1048576.0
        );
    }
}
