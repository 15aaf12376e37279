#!/usr/bin/env bash
# The declared MSRV (workspace `rust-version`) must be at least the largest `rust-version`
# among the locked dependencies: otherwise the declaration promises a toolchain that cannot
# build the lock file. Clippy's `incompatible_msrv` lint (run in CI with -D warnings) checks
# the project's own use of std APIs against the same declaration.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo metadata --format-version 1 --locked | python3 -c '
import json, sys
m = json.load(sys.stdin)
key = lambda v: tuple(int(x) for x in (v.split(".") + ["0", "0"])[:3])
members = set(m["workspace_members"])
declared = {p["rust_version"] for p in m["packages"] if p["id"] in members and p.get("rust_version")}
deps = [(p["rust_version"], p["name"], p["version"]) for p in m["packages"] if p["id"] not in members and p.get("rust_version")]
need = max(deps, key=lambda d: key(d[0]))
low = [d for d in declared if key(d) < key(need[0])]
print(f"declared rust-version {sorted(declared)}; largest among locked dependencies {need[0]} ({need[1]} {need[2]})")
if low:
    sys.exit(f"MSRV check failed: declared {low} is below {need[0]} needed by {need[1]} {need[2]}")
'
