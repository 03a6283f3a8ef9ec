//! The conformance grid on thumbv7em (in QEMU) must match the host bit for bit.
//!
//! Ignored by default because it cross-builds and needs `qemu-system-arm`; `tests/all.sh`
//! runs it with `cargo test --workspace -- --ignored`. Without QEMU it fails, it never skips.

use std::time::Instant;
use target_check::host::{build_elf, run_qemu, QemuConfig};
use target_check::{parse_report, write_report};

/// The case lines of a report, failing the test with the raw output if it is malformed.
fn case_lines(side: &str, output: &str) -> Vec<String> {
    let mut lines = Vec::new();
    if let Err(e) = parse_report(output, |l| lines.push(l.to_owned())) {
        panic!("{side} report unreadable: {e}\n--- {side} output ---\n{output}");
    }
    lines
}

#[test]
#[ignore = "cross-builds for thumbv7em and needs qemu-system-arm (run by tests/all.sh)"]
fn conformance_matches_between_host_and_qemu() {
    let mut host_report = String::new();
    write_report(&mut host_report).expect("formatting into a String cannot fail");
    let host = case_lines("host", &host_report);

    let t = Instant::now();
    let elf = build_elf("target-check", "target-check");
    eprintln!("cross build: {:.1} s", t.elapsed().as_secs_f64());

    let run = run_qemu(&elf, &QemuConfig::default());
    eprintln!("qemu run: {:.2} s", run.elapsed.as_secs_f64());
    assert!(
        run.success(),
        "QEMU run failed (exit code {:?}, timed out: {})\n--- stdout ---\n{}\n--- stderr ---\n{}",
        run.code,
        run.timed_out,
        run.stdout,
        run.stderr
    );
    let target = case_lines("target", &run.stdout);

    assert!(!host.is_empty(), "the conformance grid is empty");
    if let Some((i, (h, t))) = host
        .iter()
        .zip(&target)
        .enumerate()
        .find(|(_, (h, t))| h != t)
    {
        panic!("first difference at line {i}:\n  host:   {h}\n  target: {t}");
    }
    assert_eq!(
        host.len(),
        target.len(),
        "host has {} cases, target {}",
        host.len(),
        target.len()
    );
    eprintln!("{} cases identical on host and thumbv7em", host.len());
}
