//! The whole calibration on simulated recordings of a machine whose constants are known:
//! air moves -> friction, a speed sweep -> spindle idle, cuts of known engagement with the
//! paper's Table 2 material -> cutting coefficients, each step reading the machine file the
//! step before wrote. Noise, friction, a current offset and a broken idle line are in the
//! simulation; the recovered constants must match the simulated ones within the tolerances
//! README.md states ("Calibrate your machine"). What it writes stays in
//! `target/tmp/calibrate-whole/` for tests/all.sh's firmware build with it.

use estimator_core::drive::SpindleModel;
use estimator_core::monitor::Input;
use estimator_core::TABLE2;
use host_sim::calibrate::{run, CalibrateCmd, Common};
use host_sim::replay::load_monitor_config;
use host_sim::sim::{self, scenario::Scenario};
use std::path::{Path, PathBuf};

/// Kept after the test: tests/all.sh builds the firmware from what it writes there.
fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("calibrate-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// One feed axis of the board: the data-sheet constants (1.2 N m/A, 10 mm lead, 90 %) with
/// the given offset [A], Coulomb [N] and viscous [N per mm/min] friction.
fn axis(offset_a: f64, coulomb_n: f64, viscous: f64) -> String {
    format!(
        "[[input.motor.feed.axes]]\ntorque_constant_nm_per_a = 1.2\nscrew_lead_mm = 10.0\n\
         efficiency = 0.9\ncurrent_offset_a = {offset_a:?}\ncoulomb_n = {coulomb_n:?}\n\
         viscous_n_per_mm_min = {viscous:?}\nstiction_band_mm_min = 1.0\nsign = 1.0\n"
    )
}

/// The simulated machine: the drive's data-sheet constants, its friction and offset, the
/// spindle's torque constant and idle current (a slope change at 6000 rpm).
fn machine() -> String {
    format!(
        r#"
sample_rate_hz = 10000.0
seed = 7
material = "table2"
[tool]
radius_mm = 8.0
flutes = 4
helix_deg = 30.0
[input.motor.feed]
two_axis = false
{}{}[input.motor.spindle.current]
torque_constant_nm_per_a = 0.8
idle_current_a = [
  {{ from_rpm = 0.0, slope = 1e-4, intercept = 0.5 }},
  {{ from_rpm = 6000.0, slope = 3e-4, intercept = -0.7 }},
]
[signal]
feed_noise = 0.01
spindle_noise = 0.05
feed_lag_s = 0.0005
spindle_lag_s = 0.002
"#,
        axis(0.05, 40.0, 0.02),
        axis(0.0, 0.0, 0.0)
    )
}

/// What the user knows before calibrating: the data sheets, no friction, no idle.
fn base() -> String {
    format!(
        r#"
max_rpm = 15000.0
[estimator]
mode = "down"
[estimator.tool]
radius_mm = 8.0
flutes = 4
helix_deg = 30.0
[input.motor.feed]
two_axis = false
{}{}[input.motor.spindle.current]
torque_constant_nm_per_a = 0.8
idle_current_a = [{{ from_rpm = 0.0, slope = 0.0, intercept = 0.0 }}]
"#,
        axis(0.0, 0.0, 0.0),
        axis(0.0, 0.0, 0.0)
    )
}

fn simulate(d: &Path, name: &str, segments: &str) -> PathBuf {
    let text = format!("{}\n{segments}", machine());
    let sc = Scenario::from_toml(&text, name).expect("scenario");
    let path = d.join(format!("{name}.csv"));
    let f = std::io::BufWriter::new(std::fs::File::create(&path).expect("trace file"));
    sim::write_trace(&sc, f).expect("simulate");
    path
}

fn common(d: &Path, config: Option<&Path>, output: &str) -> Common {
    Common {
        config: config.map(Path::to_path_buf),
        output: d.join(output),
        report_dir: Some(d.join("report")),
    }
}

fn rel(got: f32, want: f32) -> f32 {
    (got / want - 1.0).abs()
}

#[test]
fn whole_calibration_recovers_the_simulated_machine() {
    let d = dir("whole");
    // 1. Air moves: 200, 800, 2400 mm/min each way, the spindle turning.
    let mut air = String::new();
    for (v, angle) in [
        (200.0, 0.0),
        (200.0, 180.0),
        (800.0, 0.0),
        (800.0, 180.0),
        (2400.0, 0.0),
        (2400.0, 180.0),
    ] {
        air += &format!(
            "[[segment]]\nduration_s = 1.2\nrpm = 1000.0\nfeed_mm_min = {v}\ndr_mm = 0.0\n\
             da_mm = 0.0\nfeed_angle_deg = {angle}\n"
        );
    }
    let air = simulate(&d, "air", &air);
    // 2. Speed sweep, no feed.
    let mut sweep = String::new();
    for rpm in [
        500.0, 1500.0, 2500.0, 3500.0, 4500.0, 5500.0, 7000.0, 8500.0, 10000.0, 12000.0,
    ] {
        sweep += &format!(
            "[[segment]]\nduration_s = 1.0\nrpm = {rpm}\nfeed_mm_min = 0.0\ndr_mm = 0.0\n\
             da_mm = 0.0\n"
        );
    }
    let sweep = simulate(&d, "sweep", &sweep);
    // 3. Cuts: R_r 0.5, 1, 2 at Table 2's feeds, R_a 0.5, 600 rpm, 2.5 s each.
    let (mut cuts, mut plan, mut t) = (String::new(), String::new(), 0.0);
    for dr in [4.0, 8.0, 16.0] {
        for tc in [0.1042, 0.2, 0.3, 0.4667] {
            cuts += &format!(
                "[[segment]]\nduration_s = 2.5\nrpm = 600.0\nfeed_mm_min = {}\ndr_mm = {dr}\n\
                 da_mm = 4.0\n",
                tc * 4.0 * 600.0
            );
            plan += &format!(
                "[[cut]]\ntrace = \"cuts.csv\"\ndr_mm = {dr}\nda_mm = 4.0\nfrom_s = {}\nto_s = {}\n",
                t + 1.0,
                t + 2.5
            );
            t += 2.5;
        }
    }
    simulate(&d, "cuts", &cuts);
    std::fs::write(d.join("plan.toml"), plan).expect("plan");
    std::fs::write(d.join("base.toml"), base()).expect("base");

    run(&CalibrateCmd::Friction {
        common: common(&d, Some(&d.join("base.toml")), "m1.toml"),
        traces: vec![air],
    })
    .expect("calibrate friction");
    run(&CalibrateCmd::Spindle {
        common: common(&d, Some(&d.join("m1.toml")), "m2.toml"),
        breaks: None,
        traces: vec![sweep],
    })
    .expect("calibrate spindle");
    run(&CalibrateCmd::Cutting {
        common: common(&d, Some(&d.join("m2.toml")), "m3.toml"),
        plan: d.join("plan.toml"),
        poly_output: None,
        linear_output: None,
    })
    .expect("calibrate cutting");

    let m = load_monitor_config(Some(&d.join("m3.toml")), Some(10_000.0))
        .expect("calibrated machine file");
    let Input::Motor { feed, spindle } = &m.config.input else {
        panic!("motor input expected");
    };
    let x = &feed.axes[0];
    eprintln!("{x:?}\n{spindle:?}\n{:?}", m.config.estimator.coeffs);
    assert!((x.current_offset_a - 0.05).abs() < 0.002, "{x:?}");
    assert!(rel(x.coulomb_n, 40.0) < 0.05, "{x:?}");
    assert!(rel(x.viscous_n_per_mm_min, 0.02) < 0.05, "{x:?}");
    let SpindleModel::Current { idle_current_a, .. } = spindle else {
        panic!("current model expected");
    };
    // The idle line: within 1 % at every speed of the sweep (the break is found between
    // 5500 and 7000 rpm).
    let want = |rpm: f32| {
        if rpm < 6000.0 {
            0.5 + 1e-4 * rpm
        } else {
            -0.7 + 3e-4 * rpm
        }
    };
    for rpm in [500.0f32, 3000.0, 5500.0, 7000.0, 9000.0, 12000.0] {
        let got = idle_current_a.eval(rpm);
        assert!(
            rel(got, want(rpm)) < 0.01,
            "idle at {rpm}: {got} vs {}",
            want(rpm)
        );
    }
    assert_eq!(idle_current_a.lines.len(), 2, "{idle_current_a:?}");
    let c = m.config.estimator.coeffs;
    assert!(rel(c.ks.k, TABLE2.ks.k) < 0.03, "{c:?}");
    assert!((c.ks.p - TABLE2.ks.p).abs() < 0.02, "{c:?}");
    assert!(rel(c.r1.k, TABLE2.r1.k) < 0.05, "{c:?}");
    assert!((c.r1.p - TABLE2.r1.p).abs() < 0.04, "{c:?}");
    assert_eq!(c.r2, TABLE2.r2, "r2 kept: no axial force");
    // What the laws leave unexplained, as the estimator's gain uncertainty: the noise of
    // the simulation averaged over each cut's teeth is well under 1 %.
    let g = m.config.estimator.gain_uncertainty;
    assert!(g > 0.0 && g < 0.01, "gain_uncertainty {g}");
    assert!(rel(c.tc_fit_mm.0, 0.1042) < 0.01 && rel(c.tc_fit_mm.1, 0.4667) < 0.01);
    // The polynomial, the linear set and the reports are written beside.
    for f in [
        "m3.fxt_poly.rs",
        "m3.linear.toml",
        "report/friction.svg",
        "report/cutting.md",
    ] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    // The calibrated machine file drives replay: depths of the cuts come back.
    let mut reader = host_sim::trace::TraceReader::open(&d.join("cuts.csv")).expect("cuts trace");
    let mut cfg = m.config.clone();
    cfg.sample_rate_hz = 10_000.0;
    let mut err = Vec::new();
    host_sim::replay::replay(&mut reader, &cfg, |rec, truth| {
        if rec.status.is_valid() && truth.dr_mm.is_finite() {
            err.push((
                (rec.dr_mm / truth.dr_mm - 1.0).abs(),
                (rec.da_mm / truth.da_mm - 1.0).abs(),
            ));
        }
    })
    .expect("replay");
    assert!(err.len() > 300, "{} valid records", err.len());
    let p95 = |k: usize| {
        let mut v: Vec<f32> = err.iter().map(|e| if k == 0 { e.0 } else { e.1 }).collect();
        v.sort_by(f32::total_cmp);
        v[v.len() * 95 / 100]
    };
    assert!(
        p95(0) < 0.05 && p95(1) < 0.05,
        "p95 d_r {} d_a {}",
        p95(0),
        p95(1)
    );
    // ... and `estimate` reads its [estimator] table as a tool file.
    let est = host_sim::config::load_estimator_config(Some(&d.join("m3.toml"))).expect("tool file");
    assert_eq!(est, m.config.estimator);
    // For the firmware build of tests/all.sh: the machine as Rust (the polynomial is
    // already beside it).
    let machine = estimator_core::MachineConfig {
        monitor: m.config.clone(),
        alarms: m.alarms,
        front_end: m.front_end,
    };
    let rs = host_sim::machine_rs::render(&machine, "m3.toml").expect("machine-rs");
    std::fs::write(d.join("m3.machine.rs"), rs).expect("write m3.machine.rs");
}

/// What a calibration cannot tell from the recordings is an error that says what to record.
#[test]
fn missing_recordings_are_errors_that_say_what_to_record() {
    let d = dir("errors");
    std::fs::write(d.join("base.toml"), base()).expect("base");
    let one_way = simulate(
        &d,
        "one_way",
        "[[segment]]\nduration_s = 1.0\nrpm = 1000.0\nfeed_mm_min = 300.0\ndr_mm = 0.0\nda_mm = 0.0\n\
         [[segment]]\nduration_s = 1.0\nfeed_mm_min = 900.0\n",
    );
    let no_v = simulate(
        &d,
        "no_velocity",
        "[output]\nvelocity = false\n[[segment]]\nduration_s = 1.0\nrpm = 1000.0\n\
         feed_mm_min = 300.0\ndr_mm = 0.0\nda_mm = 0.0\n",
    );
    let err = |cmd: CalibrateCmd| format!("{:#}", run(&cmd).expect_err("accepted"));
    let friction = |trace: PathBuf| CalibrateCmd::Friction {
        common: common(&d, Some(&d.join("base.toml")), "out.toml"),
        traces: vec![trace],
    };
    let e = err(friction(one_way.clone()));
    assert!(e.contains("both directions"), "{e}");
    let e = err(friction(no_v));
    assert!(e.contains("feed_vx_mm_min"), "{e}");
    let e = err(CalibrateCmd::Spindle {
        common: common(&d, Some(&d.join("base.toml")), "out.toml"),
        breaks: None,
        traces: vec![one_way],
    });
    assert!(e.contains("at least two"), "{e}");
    assert!(
        !d.join("out.toml").exists(),
        "a failed step wrote its output"
    );
}

/// Paper 003's FANUC spindle: idle load in whole percent from a 20 Hz load meter, with the
/// slope change at 11 000 rpm. The lines come back within the meter's half-percent step,
/// and the break is found between the speeds either side of 11 000 rpm.
#[test]
fn fanuc_idle_load_with_its_break_at_11000_rpm() {
    let d = dir("fanuc");
    let load = r#"
[input.motor.spindle.load]
idle_load_pct = [
  { from_rpm = 0.0, slope = 0.0001, intercept = -0.2892 },
  { from_rpm = 11000.0, slope = 0.0014, intercept = -14.917 },
]
low_winding_load_ratio = [[1000.0, 23.0], [1750.0, 13.3], [2300.0, 13.3], [3000.0, 13.3], [4000.0, 13.3], [5000.0, 10.9], [6000.0, 9.1]]
high_winding_load_ratio = [[5000.0, 10.9], [6000.0, 9.1], [10000.0, 9.1], [12000.0, 9.1], [15000.0, 9.1], [18000.0, 10.3], [20000.0, 11.2]]
switch_rpm = 3568.0
"#;
    let machine = machine()
        .replace("sample_rate_hz = 10000.0", "sample_rate_hz = 20000.0")
        .split("[input.motor.spindle.current]")
        .next()
        .expect("machine head")
        .to_string()
        + load
        + "[signal]\nspindle_noise = 0.3\n";
    let mut sweep = String::new();
    for rpm in [
        2000, 4000, 6000, 8000, 10000, 12000, 14000, 16000, 18000, 20000,
    ] {
        sweep += &format!(
            "[[segment]]\nduration_s = 1.0\nrpm = {rpm}.0\nfeed_mm_min = 0.0\ndr_mm = 0.0\n\
             da_mm = 0.0\n"
        );
    }
    let sc = Scenario::from_toml(&format!("{machine}\n{sweep}"), "fanuc").expect("scenario");
    let trace = d.join("sweep.csv");
    let f = std::io::BufWriter::new(std::fs::File::create(&trace).expect("trace file"));
    sim::write_trace(&sc, f).expect("simulate");
    let base = base()
        .replace("max_rpm = 15000.0", "max_rpm = 24000.0")
        .split("[input.motor.spindle.current]")
        .next()
        .expect("base head")
        .to_string()
        + load;
    std::fs::write(d.join("base.toml"), base).expect("base");
    run(&CalibrateCmd::Spindle {
        common: common(&d, Some(&d.join("base.toml")), "m.toml"),
        breaks: None,
        traces: vec![trace],
    })
    .expect("calibrate spindle");
    let m = load_monitor_config(Some(&d.join("m.toml")), Some(20_000.0)).expect("machine file");
    let Input::Motor {
        spindle: SpindleModel::Load { idle_load_pct, .. },
        ..
    } = &m.config.input
    else {
        panic!("load model expected");
    };
    let want = |rpm: f32| {
        if rpm < 11000.0 {
            1e-4 * rpm - 0.2892
        } else {
            1.4e-3 * rpm - 14.917
        }
    };
    for rpm in [2000.0f32, 6000.0, 10000.0, 12000.0, 16000.0, 20000.0] {
        let got = idle_load_pct.eval(rpm);
        assert!(
            (got - want(rpm)).abs() < 0.5,
            "{rpm} rpm: {got} vs {}",
            want(rpm)
        );
    }
    assert_eq!(idle_load_pct.lines.len(), 2, "{idle_load_pct:?}");
    let from = idle_load_pct.lines[1].from_rpm;
    assert!(from > 10000.0 && from < 12000.0, "{idle_load_pct:?}");
}
