//! `host-sim evaluate-alarms`: a setup the simulator cannot mean is refused before any
//! case runs, with the option named.

use std::process::Command;

fn evaluate(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("evaluate-alarms")
        .args(args)
        .output()
        .expect("host-sim runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_current_loop_lag_out_of_range_is_refused() {
    for option in ["--lag-s", "--monitor-lag-s"] {
        for lag in ["-0.0001", "NaN", "inf", "0.02"] {
            let (ok, err) = evaluate(&[option, lag, "--case", "break:0"]);
            assert!(!ok, "{option} {lag} ran");
            assert!(
                err.contains(&format!("{option} ")) && err.contains("current-loop time constant"),
                "{option} {lag}: {err}"
            );
        }
    }
}

#[test]
fn a_calibrated_feed_out_of_range_is_refused() {
    for mm in ["0", "-0.05", "0.5"] {
        let (ok, err) = evaluate(&["--tc-fit-from", mm, "--case", "break:0"]);
        assert!(!ok, "--tc-fit-from {mm} ran");
        assert!(err.contains("--tc-fit-from"), "--tc-fit-from {mm}: {err}");
    }
}
