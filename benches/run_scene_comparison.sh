#!/usr/bin/env bash
# Planning-scene update time on a 100,000-triangle thin mesh: the node's pipeline (a
# CollisionObject's bytes decoded, cells and tree built, the checker swapped in; then MOVE and a
# re-ADD of the same geometry), and the running release node's apply_planning_scene from a C++
# Fast DDS client's request to its reply (benches/scene_apply.rs), beside coal's BVHModelOBBRSS
# build of the same triangles, in one run. Loopback only.
#
#   bash benches/run_scene_comparison.sh [NX NY]      # default 224 x 224 quads: 100,352 triangles
#
# Uses $TC_PYTHON if set, else the test venv from scripts/setup_venv.sh (made on first use).
# Prints a table; the ratio is the pipeline's ADD over coal's build (< 1: faster).
set -euo pipefail
cd "$(dirname "$0")/.."
nx="${1:-224}"
ny="${2:-$nx}"
target="${CARGO_TARGET_DIR:-target}"
log="$target/bench_scene_comparison"
mkdir -p "$log"
wall="$log/wall_${nx}x${ny}.bin"
python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"

echo "== 1/4 the wall, written by examples/dump_wall.rs"
cargo run --quiet --release --locked --example dump_wall -- "$wall" "$nx" "$ny" | tee "$log/dump.txt"

echo "== 2/4 cargo bench --bench scene_update"
cargo bench --locked --bench scene_update -- "$nx" "$ny" 7 2>&1 | tee "$log/rust.txt"

echo "== 3/4 cargo bench --bench scene_apply (the release node, a Fast DDS client)"
TC_PYTHON="$python" cargo bench --locked --bench scene_apply -- "$nx" "$ny" 7 2>&1 | tee "$log/e2e.txt"

echo "== 4/4 coal's build of the same triangles"
"$python" benches/coal_build.py "$wall" --repeat 7 | tee "$log/coal.txt"

"$python" - "$log" <<'PY'
import json, os, re, sys
log = sys.argv[1]
text = {k: open(os.path.join(log, k + ".txt")).read() for k in ("dump", "rust", "e2e", "coal")}
sums = {k: re.search(r"checksum: (vertices=\w+ triangles=\w+)", v).group(1) for k, v in text.items()}
if len(set(sums.values())) != 1:
    sys.exit(f"the meshes differ: {sums}")
coal = json.loads(re.search(r"^COAL_BUILD (.*)$", text["coal"], re.M).group(1))
ours = json.loads(re.search(r"^SCENE_UPDATE (.*)$", text["rust"], re.M).group(1))
e2e = json.loads(re.search(r"^SCENE_APPLY (.*)$", text["e2e"], re.M).group(1))
c = coal["coal_median_s"]
print(f"| {ours['triangles']:,} triangles | median of {ours['repeat']} | ratio to coal's build |")
print("|---|---:|---:|")
print(f"| coal BVHModelOBBRSS build | {c * 1e3:.1f} ms | 1 |")
for key, name in (("add_s", "ADD: decode, cells, tree, swap"), ("move_s", "MOVE"), ("readd_s", "re-ADD, same geometry, new pose")):
    print(f"| {name} | {ours[key] * 1e3:.2f} ms | {ours[key] / c:.3f} |")
runs = ", ".join(f"{x * 1e3:.0f}" for x in sorted(e2e["add_runs_s"]))
print(f"| apply_planning_scene ADD, request to reply (release node, Fast DDS client; runs {runs} ms) | {e2e['add_s'] * 1e3:.1f} ms | {e2e['add_s'] / c:.3f} |")
print(f"| apply_planning_scene REMOVE, request to reply | {e2e['remove_s'] * 1e3:.1f} ms | {e2e['remove_s'] / c:.3f} |")
PY
