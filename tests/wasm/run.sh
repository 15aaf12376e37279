#!/usr/bin/env bash
# WebAssembly check: builds pdm-wasm for wasm32-unknown-unknown (a no_std cdylib) and natively,
# shrinks the module with binaryen's `wasm-opt -Oz`, runs run.mjs in Node (that module against
# native code, bit for bit), and enforces the .wasm size budget on it. Exits 0 only if
# everything passes.
#
#   bash tests/wasm/run.sh            (from the repository root, or from anywhere)
#
# Installs what is missing: the rustup target; Node.js (apt-get) if there is no `node`; binaryen
# BINARYEN_VERSION from npm into target/binaryen (≈ 100 MB unpacked, a few seconds).
# The module shipped, tested and measured: target/pdm-out/pdm_wasm.wasm.
# Budget (see ../firmware/BUDGETS.md): .wasm ≤ WASM_LIMIT bytes. PDM_BUDGETS=warn reports an
# exceeded budget without failing (default: enforce).
set -euo pipefail

WASM_LIMIT=32768
TARGET=wasm32-unknown-unknown
BINARYEN_VERSION=132.0.0
# The WebAssembly features rustc enables by default for wasm32-unknown-unknown (Rust ≥ 1.82:
# `rustc --print cfg --target wasm32-unknown-unknown`), so that wasm-opt accepts the module and
# uses nothing beyond them.
WASM_OPT_FEATURES=(--enable-bulk-memory --enable-bulk-memory-opt --enable-call-indirect-overlong
    --enable-multivalue --enable-mutable-globals --enable-nontrapping-float-to-int
    --enable-reference-types --enable-sign-ext)

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
wasm_opt="target/binaryen/node_modules/.bin/wasm-opt"
installed_binaryen() {
    node -p "require('./target/binaryen/node_modules/binaryen/package.json').version" 2>/dev/null || true
}
if [ "$(installed_binaryen)" != "$BINARYEN_VERSION" ]; then
    echo "installing binaryen $BINARYEN_VERSION (npm) into target/binaryen"
    mkdir -p target/binaryen
    npm install --prefix target/binaryen --no-save --no-audit --no-fund --loglevel=error \
        "binaryen@$BINARYEN_VERSION"
fi
echo "binaryen $(installed_binaryen): $("$wasm_opt" --version)"

echo "==> build"
cargo build --release --target "$TARGET" --lib
cargo build --release --bin pdm-wasm-native
built="target/$TARGET/release/pdm_wasm.wasm"
native="target/release/pdm-wasm-native"
mkdir -p target/pdm-out
wasm="target/pdm-out/pdm_wasm.wasm"
"$wasm_opt" -Oz "${WASM_OPT_FEATURES[@]}" "$built" -o "$wasm"
echo "cargo build: $(stat -c %s "$built") bytes; wasm-opt -Oz: $(stat -c %s "$wasm") bytes ($wasm)"

echo "==> node run.mjs"
status=0
node run.mjs "$wasm" "$native" || status=$?

echo "==> node example.mjs (README 'Embedding')"
example_out="$(node example.mjs "$wasm")" || status=1
echo "$example_out"
grep -q '^F(sphere -> floor) = 0\.166' <<<"$example_out" || { echo "FAIL: example.mjs output" >&2; status=1; }

echo "==> budget"
size=$(stat -c %s "$wasm")
echo "WASM size: $size bytes (limit $WASM_LIMIT; before wasm-opt $(stat -c %s "$built"))"
{
    echo "wasm_size=$size"
    echo "wasm_size_before_wasm_opt=$(stat -c %s "$built")"
} >target/pdm-out/budgets.txt
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
