#!/usr/bin/env bash
# Joint-state latency while the planning scene changes (benches/scene_latency.py): the release
# node on the bundled workcell (check_motion false), a Cyclone DDS peer streaming states at RATE Hz,
# first quiet, then with a 10,000-triangle sheet added and removed at 10 Hz; then
# apply_planning_scene of a 100,000-triangle sheet timed from request to reply. Loopback only.
#
#   bash benches/run_scene_latency.sh [RATE] [SECONDS] [TRIANGLES]     # default 1000 5 10000
set -euo pipefail
cd "$(dirname "$0")/.."
rate="${1:-1000}"; seconds="${2:-5}"; triangles="${3:-10000}"
python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
cargo build --quiet --release --locked
domain=$(( 40 + $$ % 20 ))
cyclone="$(mktemp)"
cat > "$cyclone" <<'XML'
<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><Peers><Peer address="127.0.0.1"/></Peers><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>
XML
export ROS_LOCALHOST_ONLY=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_DOMAIN_ID="$domain"
target="${CARGO_TARGET_DIR:-target}"
"$target/release/thickness_collision" run --ros-args -p check_motion:=false > /dev/null 2>&1 &
node=$!
trap 'kill $node 2>/dev/null; rm -f "$cyclone"' EXIT
sleep 2
CYCLONEDDS_URI="file://$cyclone" "$python" benches/scene_latency.py "$domain" --rate "$rate" --seconds "$seconds" --triangles "$triangles"
# And apply_planning_scene of a 100,000-triangle sheet, request to reply (the goal: at most 0.5 s).
CYCLONEDDS_URI="file://$cyclone" "$python" benches/scene_latency.py "$domain" --apply 100000
