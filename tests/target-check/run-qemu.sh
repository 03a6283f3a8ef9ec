#!/usr/bin/env bash
# Runs a thumbv7em ELF (cortex-m-rt, linked with the top-level memory.x) in QEMU's
# netduinoplus2 (STM32F405) with semihosting; exits with the program's semihosting status.
#
#   tests/target-check/run-qemu.sh [--icount] ELF [extra qemu args...]
#
# --icount adds `-icount shift=0`: 1 instruction = 1 ns of virtual time, for instruction counts.
# QEMU_TIMEOUT (seconds, default 120) bounds the run; QEMU_SYSTEM_ARM overrides the binary.
# As a cargo runner:
#   CARGO_TARGET_THUMBV7EM_NONE_EABIHF_RUNNER=tests/target-check/run-qemu.sh \
#     cargo run -p target-check --target thumbv7em-none-eabihf --release
# The trace programs take their TMS1 blob at build time (`host-sim trace-bin`, see build.rs):
#   TRACE_BIN=/abs/path/trace.tms1 cargo build -p target-check --target thumbv7em-none-eabihf \
#     --release --bin monitor-replay --bin icount-bench
#   tests/target-check/run-qemu.sh target/thumbv7em-none-eabihf/release/monitor-replay
#   tests/target-check/run-qemu.sh --icount target/thumbv7em-none-eabihf/release/icount-bench
# Keep the options in step with `qemu_command` in src/host.rs.
set -euo pipefail

icount=()
if [[ ${1:-} == --icount ]]; then
    icount=(-icount shift=0)
    shift
fi
elf=${1:?usage: run-qemu.sh [--icount] ELF [extra qemu args...]}
shift

qemu=${QEMU_SYSTEM_ARM:-qemu-system-arm}
command -v "$qemu" >/dev/null || {
    echo "run-qemu.sh: $qemu not found; install it with: apt-get install -y qemu-system-arm" >&2
    exit 127
}

exec timeout "${QEMU_TIMEOUT:-120}" "$qemu" -cpu cortex-m4 -machine netduinoplus2 -nographic \
    -semihosting-config enable=on,target=native "${icount[@]}" -kernel "$elf" "$@"
