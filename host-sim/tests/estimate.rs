//! `estimate`: forces made by the core's forward model come back as the immersion they
//! were made from; bad files fail with the line and column; odd values are flagged, kept.

use estimator_core::{average_forces, Engagement, EstimatorConfig, Solver};
use host_sim::estimate::{self, Route};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Known cuts: (R_r, R_a, t_c). t_c inside Table 2's range so the status is `valid`.
const CUTS: [(f32, f32, f32); 8] = [
    (0.15, 0.5, 0.12),
    (0.3, 1.0, 0.2),
    (0.5, 1.5, 0.11),
    (0.8, 0.25, 0.3),
    (1.0, 1.0, 0.25),
    (1.3, 0.75, 0.45),
    (1.7, 2.0, 0.15),
    (1.95, 1.0, 0.35),
];

/// A per-tooth CSV from the forward model with the default tool, columns deliberately out
/// of the documented order and with extra ones.
fn forward_csv(motor: bool) -> String {
    let cfg = EstimatorConfig::default();
    let other = if motor { "ft_n" } else { "fy_n" };
    let mut s = format!("case,fx_n,{other},tc_mm,rr_true,ra_true\n");
    for (i, &(rr, ra, tc_mm)) in CUTS.iter().enumerate() {
        let f = average_forces(
            &cfg.tool,
            &cfg.coeffs,
            cfg.mode,
            Engagement { rr, ra, tc_mm },
        );
        let o = if motor { f.ft_n } else { f.fy_n };
        s += &format!("c{i},{:?},{o:?},{tc_mm:?},{rr},{ra}\n", f.fx_n);
    }
    s
}

/// Output rows as (header, rows), each row a Vec of fields.
fn parse(out: &[u8]) -> (Vec<String>, Vec<Vec<String>>) {
    let mut rd = csv::Reader::from_reader(out);
    let header = rd
        .headers()
        .expect("output header")
        .iter()
        .map(str::to_string)
        .collect();
    let rows = rd
        .records()
        .map(|r| r.expect("output row").iter().map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

fn run_lib(csv: &str, solver: Solver, route: Route) -> anyhow::Result<Vec<u8>> {
    let est = EstimatorConfig {
        solver,
        ..EstimatorConfig::default()
    }
    .build()
    .expect("config");
    let mut out = Vec::new();
    estimate::run(csv.as_bytes(), "test.csv", &mut out, &est, route)?;
    Ok(out)
}

/// Checks every row against its `rr_true`, `ra_true` within `rtol`, and its method.
fn assert_recovers(out: &[u8], rtol: f32, method: &str) {
    let (h, rows) = parse(out);
    assert_eq!(rows.len(), CUTS.len());
    let get = |r: &Vec<String>, name: &str| -> f32 {
        r[col(&h, name)].parse().expect("number in output")
    };
    for r in &rows {
        for (est, truth) in [("rr", "rr_true"), ("ra", "ra_true")] {
            let (e, t) = (get(r, est), get(r, truth));
            assert!(((e - t) / t).abs() < rtol, "{est} {e} vs {t} in {r:?}");
        }
        assert_eq!(r[col(&h, "status")], "valid", "{r:?}");
        assert_eq!(r[col(&h, "method")], method, "{r:?}");
        let dr = get(r, "dr_mm");
        assert!((dr - 8.0 * get(r, "rr")).abs() < 1e-4, "{r:?}");
    }
}

#[test]
fn motor_route_recovers_the_cut() {
    let csv = forward_csv(true);
    let out = run_lib(&csv, Solver::Inversion, Route::Auto).expect("estimate");
    assert_recovers(&out, 1e-3, "inversion");
}

#[test]
fn motor_route_default_solver_uses_the_polynomial_within_its_fit() {
    // The fitted polynomial's worst case is 0.7 % in R_r (see fxt_poly.rs); R_a follows.
    let csv = forward_csv(true);
    let out = run_lib(&csv, Solver::Auto, Route::Auto).expect("estimate");
    // The last cut (R_r 1.95) is near the slot, where the polynomial may step outside
    // its range check; every other row must come from it.
    let (h, rows) = parse(&out);
    let methods: Vec<&str> = rows.iter().map(|r| r[col(&h, "method")].as_str()).collect();
    assert!(
        methods[..CUTS.len() - 1].iter().all(|m| *m == "polynomial"),
        "{methods:?}"
    );
    for r in &rows {
        let (e, t): (f32, f32) = (
            r[col(&h, "rr")].parse().expect("rr"),
            r[col(&h, "rr_true")].parse().expect("rr_true"),
        );
        assert!(((e - t) / t).abs() < 0.01, "{r:?}");
    }
}

#[test]
fn dynamometer_route_recovers_the_cut() {
    let csv = forward_csv(false);
    let out = run_lib(&csv, Solver::Auto, Route::Auto).expect("estimate");
    assert_recovers(&out, 1e-3, "inversion");
}

#[test]
fn keeps_input_columns_in_order_and_appends_the_estimate() {
    let csv = forward_csv(true);
    let out = run_lib(&csv, Solver::Auto, Route::Auto).expect("estimate");
    let (h, rows) = parse(&out);
    assert_eq!(
        h,
        [
            "case",
            "fx_n",
            "ft_n",
            "tc_mm",
            "rr_true",
            "ra_true",
            "rr",
            "ra",
            "dr_mm",
            "da_mm",
            "status",
            "method",
            "dr_sigma_mm",
            "da_sigma_mm"
        ]
    );
    let ids: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(ids, ["c0", "c1", "c2", "c3", "c4", "c5", "c6", "c7"]);
    // Fields are copied verbatim, not re-formatted.
    let first_in = csv.lines().nth(1).expect("row");
    assert!(String::from_utf8_lossy(&out).contains(first_in));
}

#[test]
fn nan_and_other_unusable_values_are_flagged_not_dropped() {
    let csv = "tc_mm,fx_n,ft_n,note\n\
               0.2,-50,400,ok\n\
               0.2,NaN,400,nan force\n\
               inf,-50,400,inf feed\n\
               0.2,-0.1,0.5,air cut\n\
               0,-50,400,zero feed\n";
    let out = run_lib(csv, Solver::Auto, Route::Auto).expect("estimate");
    let (h, rows) = parse(&out);
    let status: Vec<&str> = rows.iter().map(|r| r[col(&h, "status")].as_str()).collect();
    assert_eq!(
        status,
        [
            "valid",
            "non_finite",
            "non_finite",
            "not_cutting",
            "non_finite"
        ]
    );
    assert_eq!(rows[1][col(&h, "fx_n")], "NaN");
    assert_eq!(rows[1][col(&h, "note")], "nan force");
    for r in &rows[1..] {
        assert_eq!(r[col(&h, "method")], "none");
        let rr: f32 = r[col(&h, "rr")].parse().expect("rr");
        assert!(rr.is_finite());
    }
}

#[test]
fn header_only_gives_header_only() {
    let out = run_lib("fx_n,tc_mm,ft_n\n", Solver::Auto, Route::Auto).expect("estimate");
    assert_eq!(
        String::from_utf8(out).expect("utf-8"),
        "fx_n,tc_mm,ft_n,rr,ra,dr_mm,da_mm,status,method,dr_sigma_mm,da_sigma_mm\n"
    );
}

fn lib_error(csv: &str, route: Route) -> String {
    match run_lib(csv, Solver::Auto, route) {
        Ok(out) => panic!("accepted: {}", String::from_utf8_lossy(&out)),
        Err(e) => format!("{e:#}"),
    }
}

#[test]
fn malformed_rows_are_errors_naming_file_line_and_column() {
    let head = "tc_mm,fx_n,ft_n\n0.2,-50,400\n";
    let e = lib_error(&format!("{head}0.2,-50\n"), Route::Auto);
    assert!(
        e.contains("test.csv line 3") && e.contains("2 fields"),
        "{e}"
    );
    let e = lib_error(&format!("{head}0.2,-50,400,7\n"), Route::Auto);
    assert!(
        e.contains("test.csv line 3") && e.contains("4 fields"),
        "{e}"
    );
    let e = lib_error(&format!("{head}0.2,-50,400\n0.2,abc,400\n"), Route::Auto);
    assert!(
        e.contains("test.csv line 4") && e.contains("`fx_n`") && e.contains("abc"),
        "{e}"
    );
    let e = lib_error(&format!("{head}0.2,-50, \n"), Route::Auto);
    assert!(
        e.contains("line 3") && e.contains("`ft_n`") && e.contains("empty"),
        "{e}"
    );
}

#[test]
fn missing_or_conflicting_columns_are_named() {
    let e = lib_error("fx_n,ft_n\n-50,400\n", Route::Auto);
    assert!(e.contains("missing column `tc_mm`"), "{e}");
    let e = lib_error("tc_mm,fx_n\n0.2,-50\n", Route::Auto);
    assert!(e.contains("`ft_n`") && e.contains("`fy_n`"), "{e}");
    let e = lib_error("tc_mm,fx_n,fy_n\n0.2,-50,100\n", Route::Motor);
    assert!(e.contains("missing column `ft_n`"), "{e}");
    let e = lib_error("tc_mm,fx_n,fy_n,ft_n\n0.2,-50,100,400\n", Route::Auto);
    assert!(e.contains("--route"), "{e}");
    let e = lib_error("tc_mm,fx_n,ft_n,rr\n0.2,-50,400,1\n", Route::Auto);
    assert!(e.contains("column `rr`"), "{e}");
    // With both pairs present, an explicit route works.
    let out = run_lib(
        "tc_mm,fx_n,fy_n,ft_n\n0.2,-50,100,400\n",
        Solver::Auto,
        Route::Dynamometer,
    )
    .expect("estimate");
    assert_eq!(parse(&out).1.len(), 1);
}

// ---- through the binary ----

fn scratch(name: &str, text: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("estimate");
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write scratch file");
    p
}

fn host_sim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("run host-sim")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn binary_writes_estimates_and_a_tool_file_changes_them() {
    let input = scratch("cuts.csv", &forward_csv(true));
    let out = host_sim(&["estimate", "--input", s(&input)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (h, default_rows) = parse(&out.stdout);
    assert_eq!(default_rows.len(), CUTS.len());

    // Same forces, a 6 mm tool: R_r (a ratio of forces) is unchanged, d_r = 6 R_r.
    let tool = scratch(
        "tool.toml",
        "solver = \"inversion\"\n[tool]\nradius_mm = 6.0\n",
    );
    let out_csv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("estimate/out.csv");
    let out = host_sim(&[
        "estimate",
        "--input",
        s(&input),
        "--tool",
        s(&tool),
        "--output",
        s(&out_csv),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty());
    let (h6, rows6) = parse(&std::fs::read(&out_csv).expect("output file"));
    assert_eq!(h, h6);
    for (d, r) in default_rows.iter().zip(&rows6) {
        let get =
            |row: &Vec<String>, name: &str| -> f32 { row[col(&h, name)].parse().expect("number") };
        assert_eq!(r[col(&h, "method")], "inversion");
        let rr = get(r, "rr");
        assert!((get(r, "dr_mm") - 6.0 * rr).abs() < 1e-4, "{r:?}");
        assert!(
            (get(d, "dr_mm") - get(r, "dr_mm")).abs() > 0.1,
            "{d:?} vs {r:?}"
        );
    }
}

#[test]
fn binary_solver_flag_overrides() {
    let input = scratch("cuts2.csv", &forward_csv(true));
    let out = host_sim(&["estimate", "--input", s(&input), "--solver", "inversion"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_recovers(&out.stdout, 1e-3, "inversion");
}

/// Runs and expects failure with a single `error: ...` line containing every `needle`.
fn assert_fails(args: &[&str], needles: &[&str]) {
    let out = host_sim(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "succeeded: {args:?}");
    assert!(err.starts_with("error: "), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
}

#[test]
fn binary_errors_are_one_line_and_name_the_problem() {
    let bad = scratch("bad.csv", "tc_mm,fx_n,ft_n\n0.2,-50,400\n0.2,x1,400\n");
    assert_fails(
        &["estimate", "--input", s(&bad)],
        &["bad.csv line 3", "`fx_n`"],
    );
    // A failed run leaves no output file (nor its temporary) that could pass for complete.
    let out_csv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("estimate/bad_out.csv");
    assert_fails(
        &["estimate", "--input", s(&bad), "--output", s(&out_csv)],
        &["bad.csv line 3"],
    );
    assert!(
        !out_csv.exists(),
        "partial output left at {}",
        out_csv.display()
    );
    assert!(!out_csv.with_extension("csv.partial").exists());
    assert_fails(
        &["estimate", "--input", "/nonexistent/in.csv"],
        &["/nonexistent/in.csv"],
    );
    let typo = scratch("typo.toml", "[tool]\nradius = 6.0\n");
    let good = scratch("good.csv", "tc_mm,fx_n,ft_n\n0.2,-50,400\n");
    assert_fails(
        &["estimate", "--input", s(&good), "--tool", s(&typo)],
        &["typo.toml", "unknown key `tool.radius`", "radius_mm"],
    );
    let neg = scratch("neg.toml", "[tool]\nradius_mm = -6.0\n");
    assert_fails(
        &["estimate", "--input", s(&good), "--tool", s(&neg)],
        &["neg.toml", "radius_mm"],
    );
    let up = scratch("up.toml", "mode = \"up\"\n");
    assert_fails(
        &[
            "estimate",
            "--input",
            s(&good),
            "--tool",
            s(&up),
            "--solver",
            "table3",
        ],
        &["Table 3"],
    );
}

#[test]
fn help_documents_columns_units_sign_and_defaults() {
    let out = host_sim(&["estimate", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "tc_mm",
        "fx_n",
        "ft_n",
        "fy_n",
        "[N]",
        "mm/tooth",
        "negative",
        "radius 8 mm",
        "4 flutes",
        "down milling",
        "Table 2",
        "non_finite",
    ] {
        assert!(
            help.contains(needle),
            "`{needle}` missing from --help:\n{help}"
        );
    }
}
