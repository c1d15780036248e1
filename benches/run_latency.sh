#!/usr/bin/env bash
# Latency of the node beside a trivial Python relay, one peer measuring both (benches/latency.py):
# JointState at 1 kHz in, CollisionReport out, receive time minus the input's stamp.
#
#   bash benches/run_latency.sh            # ~1 minute after the release build
#
# Loopback only: the node gets ROS_LOCALHOST_ONLY=1 and ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST,
# Cyclone a 127.0.0.1-only configuration without multicast.
set -euo pipefail
cd "$(dirname "$0")/.."
python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
count="${TC_LATENCY_COUNT:-5000}"
cfg="$(mktemp -d)/cyclone.xml"
cat > "$cfg" <<'XML'
<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><Peers><Peer address="127.0.0.1"/></Peers><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>
XML
export CYCLONEDDS_URI="file://$cfg" ROS_LOCALHOST_ONLY=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
cargo build --release --locked --quiet
pids=()
trap 'kill ${pids[@]} 2>/dev/null || true' EXIT

d1=$(( 200 + RANDOM % 20 )); d2=$(( d1 + 20 ))
ROS_DOMAIN_ID=$d1 target/release/thickness_collision run --params-file config/params.yaml > /dev/null 2>&1 & pids+=($!)
"$python" benches/latency.py --relay --domain "$d2" > /dev/null 2>&1 & pids+=($!)
sleep 2
node=$("$python" benches/latency.py --domain "$d1" --count "$count")
relay=$("$python" benches/latency.py --domain "$d2" --count "$count")
"$python" - "$node" "$relay" <<'PY'
import json, sys
n, r = json.loads(sys.argv[1]), json.loads(sys.argv[2])
print("| path | sent | received | latency median (ms) | latency p99 (ms) | check_seconds median (ms) | check_seconds p99 (ms) |")
print("|---|---:|---:|---:|---:|---:|---:|")
print(f"| thickness_collision node | {n['sent']} | {n['received']} | {n['latency_ms']['median']:.3f} | {n['latency_ms']['p99']:.3f} | {n['check_ms']['median']:.3f} | {n['check_ms']['p99']:.3f} |")
print(f"| trivial Python relay | {r['sent']} | {r['received']} | {r['latency_ms']['median']:.3f} | {r['latency_ms']['p99']:.3f} | - | - |")
print(f"\nnode p99 - relay p99 = {n['latency_ms']['p99'] - r['latency_ms']['p99']:.3f} ms")
PY
