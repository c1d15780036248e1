#!/usr/bin/env bash
# Peak memory of `replay` against the size of the bag: MCAP bags of 100,000 and 1,000,000 joint
# states of the bundled arm (written by rosbags through tests/peers/bag_tool.py "write_many"),
# each replayed by the release build under /usr/bin/time. Peak RSS is GNU time's %M (maximum
# resident set, file-backed pages included).
#
#   bash benches/replay_memory.sh                 # ~1 minute after the release build
#   TC_MEMORY_COUNTS="10000 100000" bash benches/replay_memory.sh
#   TC_MEMORY_STORAGE=sqlite3 bash benches/replay_memory.sh
set -euo pipefail
cd "$(dirname "$0")/.."
python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
counts="${TC_MEMORY_COUNTS:-100000 1000000}"
storage="${TC_MEMORY_STORAGE:-mcap}"
[ -x /usr/bin/time ] || { echo "replay_memory: /usr/bin/time is needed (apt-get install time)" >&2; exit 1; }
cargo build --release --locked --quiet --bin thickness_collision
target="$(cargo metadata --format-version 1 --no-deps | "$python" -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')"
bin="$target/release/thickness_collision"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

echo "| states | bag size (MB) | peak RSS (MiB) | seconds |"
echo "|---:|---:|---:|---:|"
for n in $counts; do
    bag="$work/bag_$n"
    printf '{"op": "write_many", "path": "%s", "storage": "%s", "urdf": "%s", "count": %d, "t0": 1700000000000000000, "seed": %d}' \
        "$bag" "$storage" "$PWD/config/example_workcell/robot.urdf" "$n" "$n" | "$python" tests/peers/bag_tool.py > /dev/null
    size=$(du -sb "$bag" | cut -f1)
    /usr/bin/time -o "$work/time" -f '%M %e' "$bin" replay "$bag" > "$work/out" 2> "$work/err" \
        || { cat "$work/err" >&2; exit 1; }
    grep -q "states: $n," "$work/out" || { echo "replay_memory: expected $n states:" >&2; cat "$work/out" >&2; exit 1; }
    read -r kib secs < "$work/time"
    awk -v n="$n" -v b="$size" -v k="$kib" -v s="$secs" 'BEGIN { printf "| %d | %.1f | %.1f | %.1f |\n", n, b / 1e6, k / 1024, s }'
    rm -rf "$bag"
done
