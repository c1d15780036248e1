#!/usr/bin/env bash
# Large messages (issue 14, part 4): how long a late-joining Fast DDS reader (C++,
# benches/latency/latency.cpp latejoin: RViz's QoS for latched markers, reliable, transient local,
# keep last 1) waits for
#   - the node's latched collision_markers/cells on a 1,002,528-triangle wall, for several
#     marker_max_cells (the node started and done publishing before the reader starts), and
#   - a latched std_msgs/String of several MB on robot_description, from ros2-client
#     (examples/ros_relay.rs latched: RustDDS sending) and from Fast DDS (latency.cpp latched).
# Time is from the reader's participant creation to the whole sample taken (discovery included).
#
#   bash benches/run_large_messages.sh                   # ~3 minutes after the builds
#   TC_LARGE_CELLS="20000 2000" TC_LARGE_BYTES="4000000" bash benches/run_large_messages.sh
#
# Loopback only, in a private network namespace when unshare is allowed (as run_latency.sh).
# ROS_DOMAIN_ID 187-189.
set -euo pipefail
cd "$(dirname "$0")/.."
cells="${TC_LARGE_CELLS:-20000 10000 5000 2000 1000}"
sizes="${TC_LARGE_BYTES:-1000000 4000000 8000000}"
timeout_s="${TC_LARGE_TIMEOUT:-10}"
export ROS_LOCALHOST_ONLY=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
export TC_PYTHON="$python"

if [ -z "${TC_LARGE_IN_NS:-}" ] && unshare -n true 2>/dev/null; then
    export TC_LARGE_IN_NS=1
    cargo build --release --locked --quiet --bin thickness_collision --example ros_relay
    bash tests/peers/fastdds/build.sh latency benches/latency/latency.cpp > /dev/null
    exec unshare -n bash -c 'ip link set lo up && exec bash "$0" "$@"' "$0" "$@"
fi
network="private network namespace (lo only)"
[ -n "${TC_LARGE_IN_NS:-}" ] || { network="host namespace, 127.0.0.1 only"; cargo build --release --locked --quiet --bin thickness_collision --example ros_relay; }
peer=$(bash tests/peers/fastdds/build.sh latency benches/latency/latency.cpp)

work=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; rm -rf "$work"' EXIT
"$python" benches/latency/make_wall.py "$work" > /dev/null

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $network; reader times out after ${timeout_s} s"
echo
echo "| sample | sender | size (MB) | matched (ms) | received (ms) | received after match (ms) |"
echo "|---|---|---:|---:|---:|---:|"
row() {  # row LABEL SENDER JSON
    "$python" - "$1" "$2" "$3" <<'PY'
import json, sys
label, sender, j = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
size = f"{j['bytes'] / 1e6:.1f}" if "bytes" in j else "-"
if j["received"]:
    print(f"| {label} | {sender} | {size} | {j['matched_ms']:.0f} | {j['received_ms']:.0f} | {j['after_match_ms']:.0f} |")
else:
    print(f"| {label} | {sender} | - | {j['matched_ms']:.0f} | not within the timeout | - |")
PY
}

d=187
for n in $cells; do
    ROS_DOMAIN_ID=$d target/release/thickness_collision run --params-file config/params.yaml --environment "$work/environment.urdf" \
        --ros-args -p "marker_max_cells:=$n" > "$work/node.log" 2>&1 &
    pid=$!
    pids+=($pid)
    for _ in $(seq 120); do grep -q "^  subscribes" "$work/node.log" && break; sleep 0.5; done
    sleep 1  # the markers are published right after the banner
    j=$("$peer" latejoin "$d" rt/collision_markers/cells markers "$timeout_s" || true)
    row "cell markers, marker_max_cells $n" "node (RustDDS)" "$j"
    kill -TERM "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
done

d=188
for b in $sizes; do
    ROS_DOMAIN_ID=$d target/release/examples/ros_relay latched rt_probe "$b" 60 > /dev/null 2>&1 &
    pid=$!
    pids+=($pid)
    sleep 2
    j=$("$peer" latejoin "$d" rt/rt_probe string "$timeout_s" || true)
    row "std_msgs/String (robot_description-sized)" "ros2-client (RustDDS)" "$j"
    kill "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    "$peer" latched "$d" rt/rt_probe "$b" 60 > /dev/null 2>&1 &
    pid=$!
    pids+=($pid)
    sleep 2
    j=$("$peer" latejoin "$d" rt/rt_probe string "$timeout_s" || true)
    row "std_msgs/String (robot_description-sized)" "Fast DDS (C++)" "$j"
    kill "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
done
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
