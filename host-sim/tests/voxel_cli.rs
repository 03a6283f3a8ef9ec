//! `host-sim voxel` end to end through `voxel::run`: files in, CSV trace and height map
//! out; the CSV toolpath form against the G-code form of the same motion; errors that
//! name the file and line.

use host_sim::voxel::{run, VoxelArgs, CSV_HEADER};
use std::path::{Path, PathBuf};

/// A scratch directory of this test process.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("voxel-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

fn args(toolpath: &Path, steps_csv: Option<PathBuf>, heightmap: Option<PathBuf>) -> VoxelArgs {
    VoxelArgs {
        stock: "0,-8,-3,16,-2.5,0".into(),
        voxel_mm: 0.15,
        tool: "radius=5,flutes=3,helix=30,length=10".into(),
        toolpath: toolpath.to_path_buf(),
        steps_csv,
        start: Some("-6,0,-2".into()),
        heightmap,
        ..VoxelArgs::default()
    }
}

/// Rows of a step CSV as numbers (header checked).
fn read_trace(p: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(p).expect("trace");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(CSV_HEADER));
    lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().expect("number"))
                .collect()
        })
        .collect()
}

#[test]
fn gcode_and_timed_csv_give_the_same_trace() {
    let d = scratch("same");
    // A 2 mm deep, 2.5 mm wide side cut along +X at 900 mm/min, 6000 rpm (0.05 mm/tooth): 1.2 s.
    let nc = d.join("cut.nc");
    std::fs::write(&nc, "G21 G90\nS6000 M3\nG1 X12 F900 (cut)\n").expect("write");
    // The same motion as a CNC would stream it: positions at 25 Hz.
    let csv = d.join("cut.csv");
    let mut text = String::from("time_s,x_mm,y_mm,z_mm,spindle_rpm\n");
    for i in 0..=30 {
        let t = i as f64 * 0.04;
        text += &format!("{t},{},0,-2,6000\n", -6.0 + 15.0 * t);
    }
    std::fs::write(&csv, text).expect("write");
    let (out_nc, out_csv) = (d.join("nc.csv"), d.join("csv.csv"));
    let png = d.join("top.png");
    run(&args(&nc, Some(out_nc.clone()), Some(png.clone()))).expect("g-code run");
    run(&args(&csv, Some(out_csv.clone()), None)).expect("csv run");
    let (a, b) = (read_trace(&out_nc), read_trace(&out_csv));
    assert_eq!(a.len(), b.len());
    assert_eq!(a.len(), 2880, "1.2 s at 6000 rpm, 24 steps/rev");
    let mean = |t: &[Vec<f64>], col: usize| t.iter().map(|r| r[col]).sum::<f64>() / t.len() as f64;
    for col in [9, 10, 11, 12, 15] {
        let (x, y) = (mean(&a, col), mean(&b, col));
        assert!(
            (x - y).abs() <= 1e-3 * x.abs().max(1.0),
            "column {col}: {x} vs {y}"
        );
    }
    // Cutting happened: down milling (material on -Y of a +X cut) pushes the tool to +X.
    assert!(mean(&a, 9) > 1.0 && mean(&a, 12) > 0.01);
    let png_bytes = std::fs::read(&png).expect("png");
    assert_eq!(&png_bytes[1..4], b"PNG");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn errors_name_file_and_line() {
    let d = scratch("errors");
    let nc = d.join("bad.nc");
    std::fs::write(&nc, "G21\nS6000\nG1 X5 Y2 F100\nG2 X8 Y2 R1\n").expect("write");
    let e = format!("{:#}", run(&args(&nc, None, None)).expect_err("bad arc"));
    assert!(
        e.contains("bad.nc:4: R1 is smaller than half the chord"),
        "{e}"
    );
    let csv = d.join("bad.csv");
    std::fs::write(
        &csv,
        "time_s,x_mm,y_mm,z_mm,spindle_rpm\n0,0,0,0,6000\n0.04,1,0,0\n",
    )
    .expect("write");
    let e = format!("{:#}", run(&args(&csv, None, None)).expect_err("short row"));
    assert!(e.contains("bad.csv line 3"), "{e}");
    let mut a = args(&nc, None, None);
    a.tool = "radius=5,flutes=2,runout=0.01".into();
    let e = format!("{:#}", run(&a).expect_err("runout"));
    assert!(e.contains("one value per flute"), "{e}");
    let mut a = args(&nc, None, None);
    a.stock = "0,0,0,1,1".into();
    let e = format!("{:#}", run(&a).expect_err("stock"));
    assert!(e.contains("--stock: expected 6 numbers"), "{e}");
    let missing = d.join("missing.nc");
    let e = format!(
        "{:#}",
        run(&args(&missing, None, None)).expect_err("missing")
    );
    assert!(e.contains("missing.nc"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}
