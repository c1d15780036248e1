#!/usr/bin/env bash
# Joint-state latency while the planning scene changes, with the C++ Fast DDS instruments: the
# release node on the bundled workcell (check_motion false); benches/latency/latency.cpp sends the
# arm's state at RATE Hz for SECONDS and times each report (receive minus send, one host clock),
# first quiet, then while the Fast DDS peer (tests/peers/fastdds/peer.cpp `publish`) writes on
# `collision_object` an ADD of a TRIANGLES-triangle sheet (fresh geometry each time, from
# examples/scene_messages.rs) and its REMOVE in turn, each at 10 Hz. Both senders serialise in
# C++ (a few hundred µs per 240 kB message): what is left is the node, and the two cores.
#
#   bash benches/run_scene_latency.sh [RATE] [SECONDS] [TRIANGLES]     # default 1000 5 10000
#   TC_SCENE_PIN=1 bash benches/run_scene_latency.sh                   # senders on CPU 0, the node on CPU 1
#
# Loopback only: the node with ROS_LOCALHOST_ONLY=1, the peers' UDPv4 transports on 127.0.0.1;
# the whole run inside a private network namespace (unshare -n, only lo) when unshare is allowed.
set -euo pipefail
cd "$(dirname "$0")/.."
rate="${1:-1000}"; seconds="${2:-5}"; triangles="${3:-10000}"
python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
export TC_PYTHON="$python" ROS_LOCALHOST_ONLY=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
if [ -z "${TC_SCENE_IN_NS:-}" ] && unshare -n true 2>/dev/null; then
    cargo build --release --locked --quiet --bin thickness_collision --example scene_messages
    bash tests/peers/fastdds/build.sh peer tests/peers/fastdds/peer.cpp > /dev/null
    bash tests/peers/fastdds/build.sh latency benches/latency/latency.cpp > /dev/null
    export TC_SCENE_IN_NS=1
    exec unshare -n bash -c 'ip link set lo up && exec bash "$0" "$@"' "$0" "$@"
fi
[ -n "${TC_SCENE_IN_NS:-}" ] || cargo build --release --locked --quiet --bin thickness_collision --example scene_messages
peer=$(bash tests/peers/fastdds/build.sh peer tests/peers/fastdds/peer.cpp)
latency=$(bash tests/peers/fastdds/build.sh latency benches/latency/latency.cpp)
pin_send=() pin_node=()
if [ "${TC_SCENE_PIN:-0}" = 1 ]; then pin_send=(taskset -c 0) pin_node=(taskset -c 1); fi

out=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; rm -rf "$out"' EXIT
target/release/examples/scene_messages "$out" "$triangles" 4
files=$(for k in 0 1 2 3; do printf '"%s","%s",' "$out/add_$k.cdr" "$out/remove.cdr"; done | sed 's/,$//')
domain=$(( 190 + $$ % 10 ))
export ROS_DOMAIN_ID=$domain
"${pin_node[@]}" target/release/thickness_collision run --ros-args -p check_motion:=false > "$out/node.log" 2>&1 &
node=$!
pids+=("$node")
sleep 2

# Quiet: the states alone.
"${pin_send[@]}" "$latency" measure "$domain" "$seconds" 1 "$rate" > "$out/quiet.jsonl"
# With the scene: the publisher first (it waits for the node's reader, then writes for the whole
# measurement, its 1 s warm-up included), then the same measurement.
echo "{\"cmd\":\"publish\",\"topic\":\"collision_object\",\"files\":[$files],\"rate\":20,\"seconds\":$((seconds + 2)),\"timeout\":20}" \
    | "${pin_send[@]}" "$peer" --domain "$domain" --interface 127.0.0.1 --peer 127.0.0.1 > "$out/publish.json" &
publisher=$!
pids+=("$publisher")
sleep 0.5
"${pin_send[@]}" "$latency" measure "$domain" "$seconds" 1 "$rate" > "$out/scene.jsonl"
wait "$publisher"
kill -TERM "$node" 2>/dev/null || true
wait "$node" 2>/dev/null || true

"$python" - "$out" "$rate" "$seconds" "$triangles" <<'PY'
import json, pathlib, sys
out, rate, seconds, triangles = pathlib.Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
pub = json.loads((out / "publish.json").read_text().splitlines()[-1])
rows = {}
for phase in ("quiet", "scene"):
    rows[phase] = next(x for x in map(json.loads, (out / f"{phase}.jsonl").read_text().splitlines()) if x.get("rate") == rate)
print(f"| phase ({rate} Hz, {seconds} s) | answered / sent | median µs | p99 µs | p99.9 µs | max µs |")
print("|---|---:|---:|---:|---:|---:|")
names = {"quiet": "quiet", "scene": f"{triangles:,}-triangle sheet added/removed at 10 Hz ({pub.get('sent', 0)} messages, {pub.get('late', 0)} late)"}
for phase, j in rows.items():
    print(f"| {names[phase]} | {j['answered']:,} / {j['sent']:,} | " + " | ".join(f"{j[k]:.0f}" for k in ("median_us", "p99_us", "p999_us", "max_us")) + " |")
q, s = rows["quiet"], rows["scene"]
print(f"\np99 rise {s['p99_us'] - q['p99_us']:+.0f} µs (goal <= 1000), {s['sent'] - s['answered']} unanswered (goal 0)")
print("SCENE_LATENCY " + json.dumps({"quiet": q, "scene": s, "publish": pub}))
PY
grep -h "shutting down" "$out/node.log" || true
