#!/usr/bin/env bash
# WebAssembly check: builds pdm-wasm for wasm32-unknown-unknown (a no_std cdylib) and natively,
# runs run.mjs in Node (the module against native code, bit for bit), and enforces the .wasm
# size budget. Exits 0 only if everything passes.
#
#   bash tests/wasm/run.sh            (from the repository root, or from anywhere)
#
# Installs what is missing: the rustup target; Node.js (apt-get) if there is no `node`.
# Budget (see ../firmware/BUDGETS.md): .wasm ≤ WASM_LIMIT bytes. PDM_BUDGETS=warn reports an
# exceeded budget without failing (default: enforce).
set -euo pipefail

WASM_LIMIT=32768
TARGET=wasm32-unknown-unknown

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"
sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

echo "==> tools"
if ! rustup target list --installed | grep -qx "$TARGET"; then
    rustup target add "$TARGET"
fi
if ! command -v node >/dev/null; then
    sudo_if_needed apt-get update -q
    sudo_if_needed env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends nodejs
fi
echo "node $(node --version)"

echo "==> build"
cargo build --release --target "$TARGET" --lib
cargo build --release --bin pdm-wasm-native
wasm="target/$TARGET/release/pdm_wasm.wasm"
native="target/release/pdm-wasm-native"

echo "==> node run.mjs"
status=0
node run.mjs "$wasm" "$native" || status=$?

echo "==> node example.mjs (README 'Embedding')"
example_out="$(node example.mjs "$wasm")" || status=1
echo "$example_out"
grep -q '^F(sphere -> floor) = 0\.166' <<<"$example_out" || { echo "FAIL: example.mjs output" >&2; status=1; }

echo "==> budget"
size=$(stat -c %s "$wasm")
echo "WASM size: $size bytes (limit $WASM_LIMIT)"
mkdir -p target/pdm-out
echo "wasm_size=$size" >target/pdm-out/budgets.txt
if [ "$size" -gt "$WASM_LIMIT" ]; then
    if [ "${PDM_BUDGETS:-enforce}" = warn ]; then
        echo "BUDGET EXCEEDED (not enforced: PDM_BUDGETS=warn): wasm $size > $WASM_LIMIT bytes"
    else
        echo "FAIL: budget exceeded: wasm $size > $WASM_LIMIT bytes" >&2
        status=1
    fi
fi
if [ "$status" -eq 0 ]; then echo "wasm: all checks passed"; else echo "wasm: FAILED"; fi
exit "$status"
