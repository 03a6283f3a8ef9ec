//! The fitted `f_xt` polynomials: the committed file is current, the constants compiled
//! into estimator-core are the fitted ones, the fit meets its goal, `--check` catches a
//! stale file.

use estimator_core::fxt_poly;
use estimator_core::{EstimatorConfig, MillingMode, TABLE2};
use host_sim::gen_poly::{self, COMMAND, GOAL};
use std::path::{Path, PathBuf};
use std::process::Command;

fn committed_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../estimator-core/src/fxt_poly.rs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gen_poly");
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir.join(name)
}

fn host_sim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .expect("run host-sim")
}

#[test]
fn committed_file_is_current() {
    let (text, _) = gen_poly::generate(&TABLE2, COMMAND).expect("generate");
    let path = committed_path();
    let on_disk = std::fs::read_to_string(&path).expect("read estimator-core/src/fxt_poly.rs");
    if let Some((line, want, have)) = gen_poly::first_difference(&text, &on_disk) {
        panic!(
            "estimator-core/src/fxt_poly.rs is stale (first difference at line {line}:\n  \
             generated: {want}\n  file:      {have})\nregenerate it with `{COMMAND}`"
        );
    }
}

#[test]
fn compiled_constants_are_the_fitted_ones() {
    // Text equality above says the file is current; this says rustc read every literal
    // back to the same f32, so the estimator's exact coefficient match works.
    let fits = gen_poly::fit_all(&TABLE2).expect("fit");
    let compiled = [fxt_poly::DOWN, fxt_poly::UP];
    assert_eq!(fits.len(), compiled.len());
    for (f, c) in fits.iter().zip(&compiled) {
        assert_eq!(
            &f.poly, c,
            "{} differs from the fit; run `{COMMAND}`",
            f.spec.name
        );
        assert!(
            c.coeffs == TABLE2,
            "{} was not fitted for TABLE2",
            f.spec.name
        );
    }
    assert_eq!(fxt_poly::ALL, &compiled[..]);
    assert_eq!(fxt_poly::DOWN.mode, MillingMode::Down);
    assert_eq!(fxt_poly::UP.mode, MillingMode::Up);
    for mode in [MillingMode::Down, MillingMode::Up] {
        let est = EstimatorConfig {
            mode,
            ..EstimatorConfig::default()
        }
        .build()
        .expect("default config builds");
        assert!(
            est.has_polynomial(),
            "{mode:?}: estimator found no polynomial"
        );
    }
}

#[test]
fn fit_meets_the_goal_and_is_deterministic() {
    let a = gen_poly::generate(&TABLE2, COMMAND).expect("generate");
    let b = gen_poly::generate(&TABLE2, COMMAND).expect("generate");
    assert_eq!(a.0, b.0, "two runs gave different text");
    for f in &a.1 {
        let q = f.quality;
        assert!(q.p95 < GOAL.0 && q.max < GOAL.1, "{}: {q:?}", f.spec.name);
        assert!(q.p95 <= q.max);
        // The goal check must be able to fail: a perturbed constant term shows up.
        let mut bad = f.poly;
        bad.c[0][0] += 0.05;
        let qb = gen_poly::quality(&bad);
        assert!(
            qb.p95 > GOAL.0,
            "{}: perturbation not seen: {qb:?}",
            f.spec.name
        );
    }
}

#[test]
fn fitted_polynomial_inverts_the_forward_model_at_the_grid_edges() {
    // Independent spot checks at the corners of each declared range, through `eval`
    // (with its range checks), not just `eval_raw`.
    use estimator_core::forward::Operating;
    for p in fxt_poly::ALL {
        for rr in [p.rr.0 * 1.01, 1.0, 1.9] {
            for tc in [p.tc_mm.0, 0.1, p.tc_mm.1] {
                let f = Operating::new(&p.coeffs, p.mode, rr, tc).ratio_fxt();
                let got = p.eval(f, tc).expect("inside the declared range");
                assert!(
                    ((got - rr) / rr).abs() < 0.01,
                    "{:?} R_r {rr} t_c {tc}: got {got}",
                    p.mode
                );
            }
        }
    }
}

#[test]
fn check_mode_accepts_a_current_file_and_rejects_a_stale_one() {
    let path = scratch("check.rs");
    let p = path.to_str().expect("utf-8 path");
    let out = host_sim(&["gen-poly", "--output", p]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = host_sim(&["gen-poly", "--check", "--output", p]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let text = std::fs::read_to_string(&path).expect("read");
    std::fs::write(&path, text.replacen("x_scale: (", "x_scale: (1.0 + ", 1)).expect("write");
    let out = host_sim(&["gen-poly", "--check", "--output", p]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "stale file passed --check");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains("stale") && err.contains(COMMAND), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
}

#[test]
fn coeffs_file_changes_the_fit_and_is_named_in_the_header() {
    let coeffs = scratch("coeffs.toml");
    std::fs::write(
        &coeffs,
        "ks = { k = 700.0, p = -0.4 }\nr1 = { k = 0.25, p = -0.25 }\n\
         r2 = { k = 0.12, p = 0.17 }\ntc_fit_mm = [0.05, 0.4]\n",
    )
    .expect("write coeffs");
    let out_path = scratch("custom.rs");
    let (c, o) = (
        coeffs.to_str().expect("utf-8"),
        out_path.to_str().expect("utf-8"),
    );
    let out = host_sim(&["gen-poly", "--coeffs", c, "--output", o]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&out_path).expect("read");
    assert!(
        text.contains("r1: PowerLaw { k: 0.25, p: -0.25 }"),
        "{text}"
    );
    assert!(text.contains(&format!("--coeffs {c}")), "{text}");
    assert!(text.contains("tc_fit_mm: (0.05, 0.4)"), "{text}");

    // An incomplete set is refused, naming the missing key.
    std::fs::write(&coeffs, "ks = { k = 700.0, p = -0.4 }\n").expect("write");
    let out = host_sim(&["gen-poly", "--coeffs", c, "--output", o]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("`r1`") && err.contains("coeffs.toml"), "{err}");

    // So is a misspelt one.
    std::fs::write(&coeffs, "ks = { k = 700.0, pp = -0.4 }\n").expect("write");
    let out = host_sim(&["gen-poly", "--coeffs", c, "--output", o]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("unknown key `ks.pp`"), "{err}");
}
