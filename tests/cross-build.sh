#!/usr/bin/env bash
# Cross-target builds of pdm-kernel: every target × every feature combination.
#
#   bash tests/cross-build.sh          (from the repository root, or from anywhere)
#
# Targets: thumbv7em-none-eabihf (Cortex-M4F), thumbv6m-none-eabi (Cortex-M0, no FPU, no
# compare-and-swap atomics), riscv32imac-unknown-none-elf, wasm32-unknown-unknown.
# Features: none, micromath, defmt, micromath+defmt. Missing rustup targets are installed.
# Building a library for a bare-metal target proves it needs no `std`; the firmware under
# tests/firmware (linked without a global allocator) proves it needs no heap.
# Every combination is built; a combination that cannot build is reported by name, and the
# script exits non-zero if any failed. Prints "N passed, M failed" last.
set -uo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

targets=(thumbv7em-none-eabihf thumbv6m-none-eabi riscv32imac-unknown-none-elf wasm32-unknown-unknown)
feature_sets=("" "micromath" "defmt" "micromath,defmt")

installed="$(rustup target list --installed)"
for t in "${targets[@]}"; do
    if ! grep -qx "$t" <<<"$installed"; then
        rustup target add "$t" || { echo "cannot install rustup target $t" >&2; exit 1; }
    fi
done

passed=0
failed=0
failures=()
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
for t in "${targets[@]}"; do
    for f in "${feature_sets[@]}"; do
        label="$t [${f:-no features}]"
        if cargo build --release -p pdm-kernel --target "$t" --no-default-features ${f:+--features "$f"} >"$log" 2>&1; then
            echo "ok    $label"
            passed=$((passed + 1))
        else
            echo "FAIL  $label"
            sed 's/^/      /' "$log" | grep -E '^      (error|warning: unused)|^      +(-->|= note)' | head -n 20
            failures+=("$label")
            failed=$((failed + 1))
        fi
    done
done

if [ "$failed" -gt 0 ]; then
    echo "combinations that did not build:"
    printf '  %s\n' "${failures[@]}"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
