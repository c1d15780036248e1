#!/usr/bin/env bash
# Build time on a 1,000,000-triangle wall: this crate (weld + topology + cells + BVH) beside
# coal's BVHModelOBBRSS (and python-fcl's BVHModel) built from the same triangles, in one run.
#
#   bash benches/run_build_comparison.sh          # ~3 minutes after the first compile
#
# Uses $TC_PYTHON if set, else the test venv from scripts/setup_venv.sh (made on first use).
# Prints a table; the ratio is this crate's whole build time over coal's build time (< 1: faster).
set -euo pipefail
cd "$(dirname "$0")/.."
target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$target"
wall="$target/bench_wall_708.bin"
log="$target/bench_build_comparison"
mkdir -p "$log"

python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"

echo "== 1/3 the wall, written by examples/dump_wall.rs"
cargo run --quiet --release --locked --example dump_wall -- "$wall" | tee "$log/dump.txt"

echo "== 2/3 cargo bench --bench build"
cargo bench --locked --bench build 2>&1 | tee "$log/rust.txt"

echo "== 3/3 coal (and python-fcl) build of the same triangles"
"$python" benches/coal_build.py "$wall" | tee "$log/coal.txt"

"$python" - "$target/criterion/build_1M_wall" "$log" <<'PY'
import json, os, re, sys
crit, log = sys.argv[1], sys.argv[2]
text = {k: open(os.path.join(log, k + ".txt")).read() for k in ("dump", "rust", "coal")}
sums = {k: re.search(r"checksum: (vertices=\w+ triangles=\w+)", v).group(1) for k, v in text.items()}
if len(set(sums.values())) != 1:
    sys.exit(f"the meshes differ: {sums}")
coal = json.loads(re.search(r"^COAL_BUILD (.*)$", text["coal"], re.M).group(1))
mem = dict(kv.split("=") for kv in re.search(r"^BUILD_MEMORY (.*)$", text["rust"], re.M).group(1).split())
n = coal["triangles"]

def median(stage):
    with open(os.path.join(crit, stage, "new", "estimates.json")) as f:
        return json.load(f)["median"]["point_estimate"] * 1e-9

rows = [(f"this crate: {s}", median(s)) for s in ("weld", "topology", "cells", "tree")]
ours = median("whole")
rows.append(("this crate: whole build (weld+topology+cells+tree)", ours))
rows.append((f"coal {coal['coal_version']} BVHModelOBBRSS (begin/add/endModel)", coal["coal_median_s"]))
if "fcl_median_s" in coal:
    rows.append((f"python-fcl {coal['fcl_version']} BVHModel OBBRSS", coal["fcl_median_s"]))
print()
print(f"Build of a {n:,}-triangle wavy wall (same triangles: checksum {sums['dump']}); medians")
print()
print(f"| {'build':<55} | {'time':>9} | {'triangles/s':>11} |")
print(f"|{'-' * 57}|{'-' * 10}:|{'-' * 12}:|")
for name, s in rows:
    print(f"| {name:<55} | {s * 1e3:>6.0f} ms | {n / s / 1e6:>9.2f} M |")
print()
print(f"ratio, this crate's whole build / coal's BVHModel build: {ours / coal['coal_median_s']:.2f}")
if "fcl_median_s" in coal:
    print(f"ratio, this crate's whole build / python-fcl's BVHModel build: {ours / coal['fcl_median_s']:.2f}")
print(f"memory: {float(mem['bytes_per_cell']):.0f} B per cell (ThicknessCell {mem['cell_bytes']} B + tree "
      f"{int(mem['bvh_bytes']) / int(mem['cells']):.0f} B); coal memUsage {coal['coal_bytes_per_triangle']:.0f} B per triangle")
PY
