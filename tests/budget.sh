#!/usr/bin/env bash
# The board's budgets: flash (text + data) under 64 KiB, static RAM (data + bss) under
# 16 KiB (the product's targets, BENCHMARKS.md). `bash tests/budget.sh ELF` fails when the
# ELF is over either; tests/all.sh runs it on the default and the calibrated firmware.
set -euo pipefail
elf=${1:?usage: tests/budget.sh ELF}
tool=$(command -v llvm-size || command -v size || true)
[[ -n $tool ]] || { echo "tests/budget.sh: neither llvm-size nor size (binutils) found" >&2; exit 1; }
# Berkeley format: text data bss dec hex filename, one line after the header.
read -r text data bss _ < <("$tool" "$elf" | awk 'NR == 2 { print $1, $2, $3 }')
flash=$((text + data))
ram=$((data + bss))
echo "$elf: flash $flash B of 65536, static RAM $ram B of 16384"
if ((flash >= 65536 || ram >= 16384)); then
    echo "tests/budget.sh: $elf is over the board's budget" >&2
    exit 1
fi
