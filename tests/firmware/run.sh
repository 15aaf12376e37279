#!/usr/bin/env bash
# Firmware check: builds the Cortex-M4F firmware (tests/firmware) in four variants, runs them
# under QEMU (mps2-an386, semihosting), compares with the host, decodes the defmt build with
# defmt-print, and measures and enforces the budgets. Exits 0 only if everything passes.
#
#   bash tests/firmware/run.sh            (from the repository root, or from anywhere)
#
# Installs what is missing: the rustup target, llvm-tools, qemu-system-arm (apt-get), defmt-print
# (cargo install, ≈270 s the first time). Needs no standard input.
#
# Budgets (see BUDGETS.md): flash of the kernel part with libm at order 5 ≤ FLASH_LIMIT bytes,
# peak stack of one form-factor call (order 5, CAP 25) ≤ STACK_LIMIT bytes, peak stack of
# `pair_exchange` on the pair path (examples/pair_stack.rs, order 5, CAP 25) ≤ PAIR_STACK_LIMIT.
# PDM_BUDGETS=warn reports an exceeded budget without failing (default: enforce).
set -euo pipefail

FLASH_LIMIT=16384
STACK_LIMIT=4096
PAIR_STACK_LIMIT=18432
TARGET=thumbv7em-none-eabihf
QEMU_TIMEOUT=120

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"
out="$here/target/pdm-out"
mkdir -p "$out"
failures=()
fail() { echo "FAIL: $*" >&2; failures+=("$*"); }
step() { echo; echo "==> $*"; }

# ---- tools ---------------------------------------------------------------------------------
sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

step "tools"
if ! rustup target list --installed | grep -qx "$TARGET"; then
    rustup target add "$TARGET"
fi
host="$(rustc -vV | sed -n 's/^host: //p')"
llvm_bin="$(rustc --print sysroot)/lib/rustlib/$host/bin"
if [ ! -x "$llvm_bin/llvm-size" ]; then
    rustup component add llvm-tools
fi
if ! command -v qemu-system-arm >/dev/null; then
    sudo_if_needed apt-get update -q
    sudo_if_needed env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends qemu-system-arm
fi
if ! command -v defmt-print >/dev/null; then
    echo "installing defmt-print (cargo install, a few minutes)"
    cargo install defmt-print
fi
echo "host $host; $(qemu-system-arm --version | head -1); $(defmt-print --version)"

qemu() {
    timeout "$QEMU_TIMEOUT" qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
        -semihosting-config enable=on,target=native -kernel "$1"
}

# ---- builds --------------------------------------------------------------------------------
# Each variant is copied out, since they all build to the same path.
elf="target/$TARGET/release/pdm-firmware"
build() { # name features
    step "build $1 (features: ${2:-none})"
    cargo build --release --features "$2" 2>&1 | tail -n 3 || { fail "build $1"; return 1; }
    cp "$elf" "$out/firmware-$1.elf"
}
build libm "" || true
build micromath micromath || true
build baseline baseline || true
build defmt defmt || true
# Comparison builds (flash figures printed for information, not budgeted; run and checked like
# the others): the scenes through the run-time-order API, and with concrete types instead of
# trait objects (BUDGETS.md, "Flash").
build runtime-order runtime-order || true
build generic generic || true

# ---- runs ----------------------------------------------------------------------------------
run_plain() { # name
    local log="$out/run-$1.log" status=0
    step "run $1 under QEMU"
    [ -f "$out/firmware-$1.elf" ] || { fail "no $1 firmware"; return 0; }
    qemu "$out/firmware-$1.elf" >"$log" 2>&1 || status=$?
    cat "$log"
    [ "$status" -eq 0 ] || fail "$1 firmware exited with status $status"
    grep -q '^RESULT PASS$' "$log" || fail "$1 firmware did not print RESULT PASS"
    [ "$(grep -c '^CASE .* ok$' "$log")" -eq 3 ] || fail "$1 firmware: not 3 cases ok"
}
run_plain libm
run_plain micromath
run_plain baseline
run_plain runtime-order
run_plain generic

# Same backend on both machines: the firmware's bits against a host run of the same scenes.
# Tolerance 4 ulp per case (measured: 0, bit-identical, for both backends).
compare_host() { # name features
    local log="$out/run-$1.log" hostlog="$out/host-$1.log"
    step "host run ($1) and firmware-vs-host comparison"
    cargo run --release -q -p pdm-firmware-scenes --example expected --target "$host" \
        ${2:+--features "$2"} >"$hostlog" || { fail "host run $1"; return 0; }
    cat "$hostlog"
    local n=0 name hb fb
    while read -r name hb; do
        fb="$(sed -n "s/^CASE $name .* bits=\(0x[0-9a-f]*\) .*/\1/p" "$log")"
        if [ -z "$fb" ]; then fail "$1: no firmware value for $name"; continue; fi
        local d=$(( fb > hb ? fb - hb : hb - fb ))
        echo "  $name firmware=$fb host=$hb diff=${d} ulp (tolerance 4)"
        [ "$d" -le 4 ] || fail "$1: $name differs from the host by $d ulp"
        n=$((n + 1))
    done < <(sed -n 's/^CASE \([a-z_]*\) .* bits=\(0x[0-9a-f]*\).*/\1 \2/p' "$hostlog")
    [ "$n" -eq 3 ] || fail "$1: compared $n cases, expected 3"
}
compare_host libm ""
compare_host micromath micromath

# defmt: the frames QEMU writes to stdout, decoded on the host by defmt-print.
step "run defmt build under QEMU | defmt-print"
dlog="$out/run-defmt.log"
if [ -f "$out/firmware-defmt.elf" ]; then
    status=0
    ( set -o pipefail; qemu "$out/firmware-defmt.elf" | defmt-print -e "$out/firmware-defmt.elf" ) >"$dlog" 2>&1 || status=$?
    cat "$dlog"
    [ "$status" -eq 0 ] || fail "defmt firmware | defmt-print exited with status $status"
    for want in 'INFO  pdm-firmware (defmt): backend=libm quadrature=Quadrature { order_a: 5, order_b: 5 } cap=25' \
                'INFO  negative radius -> Some(Degenerate)' \
                'INFO  CASE sphere_to_face result=Ok(' \
                'INFO  CASE shared_edge result=Ok(' \
                'INFO  CASE occluded_pair result=Ok(' \
                'INFO  RESULT PASS'; do
        grep -qF "$want" "$dlog" || fail "defmt output lacks: $want"
    done
    [ "$(grep -c 'ok=true' "$dlog")" -eq 3 ] || fail "defmt output: not 3 cases ok=true"
else
    fail "no defmt firmware"
fi

# The README's minimal firmware example (examples/minimal.rs) builds and runs.
step "build and run examples/minimal.rs (README 'Embedding')"
status=0
if cargo build --release --example minimal 2>&1 | tail -n 1; then
    qemu "target/$TARGET/release/examples/minimal" >"$out/run-minimal.log" 2>&1 || status=$?
    cat "$out/run-minimal.log"
    [ "$status" -eq 0 ] || fail "minimal example exited with status $status"
    grep -q '^F(sphere -> floor) = 0\.166' "$out/run-minimal.log" || fail "minimal example: unexpected output"
else
    fail "build examples/minimal.rs"
fi

# The pair path's stack (examples/pair_stack.rs): pair_exchange on an occluded, a straddling and
# a plain pair; the values are checked against the physical bounds there.
step "build and run examples/pair_stack.rs (pair path stack)"
status=0
if cargo build --release --example pair_stack 2>&1 | tail -n 1; then
    qemu "target/$TARGET/release/examples/pair_stack" >"$out/run-pair-stack.log" 2>&1 || status=$?
    cat "$out/run-pair-stack.log"
    [ "$status" -eq 0 ] || fail "pair_stack example exited with status $status"
    [ "$(grep -c '^PAIR [a-z]* value=' "$out/run-pair-stack.log")" -eq 3 ] || fail "pair_stack: not 3 pairs within bounds"
else
    fail "build examples/pair_stack.rs"
fi

# ---- budgets -------------------------------------------------------------------------------
step "budgets"
text_rodata() { # elf -> bytes of .text + .rodata
    "$llvm_bin/llvm-size" -A "$1" | awk '$1 == ".text" || $1 == ".rodata" { s += $2 } END { print s }'
}
over=()
if [ -f "$out/firmware-libm.elf" ] && [ -f "$out/firmware-baseline.elf" ] && [ -f "$out/firmware-micromath.elf" ]; then
    base=$(text_rodata "$out/firmware-baseline.elf")
    libm=$(text_rodata "$out/firmware-libm.elf")
    mm=$(text_rodata "$out/firmware-micromath.elf")
    flash_libm=$((libm - base))
    flash_mm=$((mm - base))
    echo "flash .text+.rodata: libm build $libm, micromath build $mm, baseline $base"
    echo "FLASH kernel part (libm, order 5): $flash_libm bytes (limit $FLASH_LIMIT)"
    echo "FLASH kernel part (micromath, order 5): $flash_mm bytes (saves $((flash_libm - flash_mm)) bytes)"
    [ "$flash_libm" -le "$FLASH_LIMIT" ] || over+=("flash $flash_libm > $FLASH_LIMIT bytes")
    kernel_part() { # variant -> kernel part of its flash, or nothing if it was not built
        [ -f "$out/firmware-$1.elf" ] && echo $(( $(text_rodata "$out/firmware-$1.elf") - base ))
    }
    flash_runtime_order="$(kernel_part runtime-order || true)"
    flash_generic="$(kernel_part generic || true)"
    echo "flash kernel part (libm), for comparison, not budgeted:" \
        "run-time-order API ${flash_runtime_order:-?} bytes, concrete types ${flash_generic:-?} bytes"
fi
# The compile-time order links order 5's Gauss table only (2 × 20 B), not the tables of every order.
if [ -f "$out/firmware-libm.elf" ]; then
    tables="$("$llvm_bin/llvm-nm" -C "$out/firmware-libm.elf" | sed -n 's/.*gauss_tables::\([A-Z0-9_]*\).*/\1/p' | sort | tr '\n' ' ')"
    echo "Gauss tables linked (libm build): $tables"
    [ "$tables" = "NODES_5_F32 WEIGHTS_5_F32 " ] || fail "the firmware links Gauss tables other than order 5's: $tables"
fi
for v in libm micromath; do
    s="$(sed -n 's/^STACK_MAX \([0-9]*\)$/\1/p' "$out/run-$v.log" 2>/dev/null || true)"
    if [ -z "$s" ]; then fail "no STACK_MAX from the $v run"; continue; fi
    echo "STACK peak of one form-factor call ($v, order 5, CAP 25): $s bytes (limit $STACK_LIMIT)"
    [ "$s" -le "$STACK_LIMIT" ] || over+=("stack ($v) $s > $STACK_LIMIT bytes")
done
pair_stack="$(sed -n 's/^PAIR_STACK_MAX \([0-9]*\)$/\1/p' "$out/run-pair-stack.log" 2>/dev/null || true)"
if [ -z "$pair_stack" ]; then
    fail "no PAIR_STACK_MAX from the pair_stack run"
else
    echo "STACK peak of pair_exchange on the pair path (libm, order 5, CAP 25): $pair_stack bytes (limit $PAIR_STACK_LIMIT)"
    [ "$pair_stack" -le "$PAIR_STACK_LIMIT" ] || over+=("pair stack $pair_stack > $PAIR_STACK_LIMIT bytes")
fi
{
    echo "flash_kernel_libm=${flash_libm:-}"
    echo "stack_pair_libm=${pair_stack:-}"
    echo "flash_kernel_micromath=${flash_mm:-}"
    echo "flash_kernel_libm_runtime_order=${flash_runtime_order:-}"
    echo "flash_kernel_libm_generic=${flash_generic:-}"
    echo "stack_libm=$(sed -n 's/^STACK_MAX \([0-9]*\)$/\1/p' "$out/run-libm.log" 2>/dev/null || true)"
    echo "stack_micromath=$(sed -n 's/^STACK_MAX \([0-9]*\)$/\1/p' "$out/run-micromath.log" 2>/dev/null || true)"
} >"$out/budgets.txt"
for o in ${over[@]+"${over[@]}"}; do
    if [ "${PDM_BUDGETS:-enforce}" = warn ]; then
        echo "BUDGET EXCEEDED (not enforced: PDM_BUDGETS=warn): $o"
    else
        fail "budget exceeded: $o"
    fi
done

echo
if [ "${#failures[@]}" -eq 0 ]; then
    echo "firmware: all checks passed"
    exit 0
fi
echo "firmware: ${#failures[@]} check(s) failed:"
printf '  %s\n' "${failures[@]}"
exit 1
