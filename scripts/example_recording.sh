#!/usr/bin/env bash
# The example recording of docs/viewing.md: the bundled arm sweeping through the bundled workcell
# for 30 s at 100 Hz, written as a rosbag2 MCAP bag by rosbags (tests/peers/bag_tool.py), then
# replayed with --out and --plot. Writes docs/replay_timeline_example.svg and leaves the bags in
# target/example_recording/ (sweep: the input, sweep_collisions: replay's output) to open in
# Foxglove or play to RViz.
#
#   bash scripts/example_recording.sh        (needs the peers' venv: scripts/setup_venv.sh)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
python="${TC_PYTHON:-/root/.cache/thickness_collision/venv/bin/python}"
work="$root/target/example_recording"
rm -rf "$work" && mkdir -p "$work"
"$python" - "$work/request.json" <<'EOF'
import json, math, sys
names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
t0 = 1_700_000_000_000_000_000
messages = []
for k in range(3000):
    s = k / 100 * 1.5
    q = [1.2 * math.sin(0.9 * s), 0.7 + 0.6 * math.sin(2.1 * s), 0.3 + 0.6 * math.sin(1.3 * s + 0.5),
         0.8 * math.sin(1.7 * s), 0.5 * math.cos(1.1 * s), 0.0]
    messages.append({"t": t0 + k * 10_000_000, "stamp": t0 + k * 10_000_000, "name": names, "position": q})
json.dump({"op": "write", "path": sys.argv[1].replace("request.json", "sweep"), "storage": "mcap", "messages": messages}, open(sys.argv[1], "w"))
EOF
"$python" "$root/tests/peers/bag_tool.py" < "$work/request.json" > /dev/null
cargo build --release --locked --manifest-path "$root/Cargo.toml" --quiet
# From the bag's folder, so the picture's header names the bag, not this machine's path.
cd "$work"
"$root/target/release/thickness_collision" replay sweep --out sweep_collisions --jsonl sweep.jsonl --plot "$root/docs/replay_timeline_example.svg"
