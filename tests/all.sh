#!/usr/bin/env bash
# The project's one "run all tests" command: `bash tests/all.sh` from anywhere.
#
# Installs what it needs first (cross target, rustfmt/clippy, QEMU when run as root), so it
# also works on a fresh machine and in CI (.ci/run). Every step must pass; the first failure
# stops the run with its exit code.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

TARGET=thumbv7em-none-eabihf

die() {
    echo "tests/all.sh: $*" >&2
    exit 1
}

# Runs one step under a visible header and reports its duration.
step() {
    echo
    echo "==> $*"
    local start=$SECONDS
    "$@"
    echo "<== ok ($((SECONDS - start)) s): $*"
}

# CI's machine has little disk (a full run once filled it): there, a build tree goes as soon
# as no later step reads it. A developer's trees stay, for the next run.
prune() {
    if [[ -n ${CI:-} ]]; then
        echo "==> CI: removing $* ($(du -sh "$@" 2>/dev/null | cut -f1 | paste -sd+))"
        rm -rf "$@"
    fi
}

# --- prerequisites -----------------------------------------------------------------------
if ! command -v cargo >/dev/null && [[ -f "${HOME:-/root}/.cargo/env" ]]; then
    # shellcheck disable=SC1091
    source "${HOME:-/root}/.cargo/env"
fi
command -v cargo >/dev/null || die "cargo not found: install Rust with rustup (https://rustup.rs)"
command -v rustup >/dev/null || die "rustup not found: the cross target is installed through it"

# Run from the workspace root, so rustup answers for the toolchain of rust-toolchain.toml.
# (Outputs are captured first: `grep -q` quitting early under pipefail would look like a miss.)
installed_targets=$(rustup target list --installed)
grep -qx "$TARGET" <<<"$installed_targets" || rustup target add "$TARGET"
installed_components=$(rustup component list --installed)
for component in rustfmt clippy; do
    grep -q "^$component" <<<"$installed_components" || rustup component add "$component"
done

if ! command -v qemu-system-arm >/dev/null; then
    if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null; then
        echo "==> installing qemu-system-arm"
        apt-get update
        DEBIAN_FRONTEND=noninteractive apt-get install -y qemu-system-arm
    else
        die "qemu-system-arm is missing and cannot be installed here (needs root and apt-get).
Install it, e.g. 'sudo apt-get install -y qemu-system-arm', then rerun."
    fi
fi

# --- checks --------------------------------------------------------------------------------
step cargo fmt --all --check
# Host lints over every member (firmware and target-check are empty mains on the host).
step cargo clippy --workspace --all-targets -- -D warnings
# The embedded code itself is only compiled for the target: lint it there too.
step cargo clippy -p firmware -p target-check --target "$TARGET" -- -D warnings

# --- host tests ----------------------------------------------------------------------------
# --workspace: all members, not just default-members.
step cargo test --workspace

# --- slow tests: QEMU (tests/target-check) and data under ../shared/data -------------------
# Every `#[ignore]`d test of every member runs here; mark new slow tests `#[ignore]` and they
# are picked up without touching this script.
step cargo test --workspace -- --ignored
prune target/debug target/qemu

# --- cross builds --------------------------------------------------------------------------
# The core builds for a no_std, no-heap target.
step cargo build -p estimator-core --target "$TARGET" --release
step cargo build -p firmware --target "$TARGET" --release
# Flash under 64 KiB and static RAM under 16 KiB (it slipped past once, unnoticed).
step bash tests/budget.sh "target/$TARGET/release/firmware"
# The firmware built from the calibration the host tests wrote (target/tmp).
step bash tests/calibrated-firmware.sh
prune target/calibrated

# --- the user's commands, end to end ---------------------------------------------------------
# README's demo, and the alarm evaluation on CI's small set (its --check fails on a false
# alarm in any set, a missed overload or teach-in excursion, fewer than 90 % of wear
# warnings, fewer than 90 % of full breakages caught or fewer than 90 % within one
# revolution).
step cargo run --release -p host-sim -- demo --out-dir target/demo-ci
step cargo run --release -p host-sim -- evaluate-alarms --set small --check
# ... and again without the servo amplifiers' current-loop lag (a machine calibrated with
# `spindle_lag_s` 0; a false alarm there once went unseen at the default 0.5 ms).
step cargo run --release -p host-sim -- evaluate-alarms --set small --check --lag-s 0

# --- later steps go here (benchmarks, golden-trace replays, ...) ---------------------------

echo
echo "tests/all.sh: all steps passed"
