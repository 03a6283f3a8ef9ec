#!/usr/bin/env bash
# The firmware built from a calibration: the machine file and f_xt polynomial that
# host-sim's calibration test wrote (host-sim/tests/calibrate.rs, run by `cargo test
# --workspace` before this) go in through FIRMWARE_MACHINE_RS and ESTIMATOR_FXT_POLY. Checks
# that the firmware compiles the calibrated configuration field for field, that the
# estimator finds the polynomial, and that the board binary still fits. A separate target
# directory keeps the default build's cache.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
TARGET=thumbv7em-none-eabihf
CAL=target/tmp/calibrate-whole
for f in m3.machine.rs m3.fxt_poly.rs; do
    [[ -f "$CAL/$f" ]] || {
        echo "tests/calibrated-firmware.sh: $CAL/$f missing: run cargo test -p host-sim --test calibrate first" >&2
        exit 1
    }
done
export FIRMWARE_MACHINE_RS="$CAL/m3.machine.rs"
export ESTIMATOR_FXT_POLY="$CAL/m3.fxt_poly.rs"
export CARGO_TARGET_DIR=target/calibrated
cargo test -p firmware --lib machine_file
cargo test -p estimator-core --test user_poly
cargo build -p firmware --bin firmware --target "$TARGET" --release
bash tests/budget.sh "$CARGO_TARGET_DIR/$TARGET/release/firmware"
