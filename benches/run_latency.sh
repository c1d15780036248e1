#!/usr/bin/env bash
# The latency instrument (issue 14, part 3): a Fast DDS C++ peer (benches/latency/latency.cpp)
# publishes sensor_msgs/JointState at 1 kHz and 10 kHz, SECONDS per rate to each answerer, and
# measures receive time minus send time of the CollisionReport carrying each state's stamp, from
# three answerers:
#   node        thickness_collision on the bundled workcell, the shipped config/params.yaml
#               (check_motion true)
#   Rust relay  examples/ros_relay.rs: ros2-client/RustDDS, the node's QoS and kind of loop, an
#               empty report per state (the floor of the node's middleware)
#   C++ relay   latency.cpp relay: Fast DDS, an empty report per state from the listener (the floor
#               of a native DDS)
# and prints one markdown table (median, p99, p99.9, max in µs; answered of sent).
#
#   bash benches/run_latency.sh [SECONDS]          # SECONDS per rate, default 10; ~2 minutes after the builds
#   TC_LATENCY_PIN=1 bash benches/run_latency.sh   # sender on CPU 0, the answerer on CPU 1 (taskset)
#   TC_LATENCY_ONLY="node cpp" ...                 # a subset of the answerers
#   TC_LATENCY_ONLY="cpp rust rust-loop node node-handover node-loop" ...
#                                                  # also the node with TC_CHECK_ON_RECEIVE=0
#                                                  # (each state handed from RustDDS's receiving
#                                                  # thread to the node's loop, as before
#                                                  # states_on_receive.rs), and the Rust relay and
#                                                  # that node with RUSTDDS_DIRECT_SEND=0 too (every
#                                                  # report sent by RustDDS's event loop, as before
#                                                  # its change 12)
#   TC_LATENCY_ROUNDS=2 ...                        # repeat the whole set
#   TC_LATENCY_MODE=sequential ...                 # one answerer after the other, SECONDS each
#                                                  # (before 2026-12-02 19:00 UTC the only way)
#   TC_LATENCY_SLICE=1 ...                         # seconds per slice in the default mode
#   TC_LATENCY_DUMP=DIR ...                        # each answered state's send stamp and latency
#                                                  # into DIR/<domain>-<rate>.csv (the last round's)
#
# By default every answerer runs at once, each on a domain of its own, and one sender feeds them
# in turn, TC_LATENCY_SLICE seconds at a time (the order rotating), until each has had SECONDS:
# this host stalls the VM for seconds at a time, and measured one after the other, a stall fell
# on one answerer and not on the one it was compared with. Fed in slices, each answerer sees a
# continuous motion of its own; an answerer not being fed is idle.
#
# Network: every participant binds to 127.0.0.1 (Fast DDS: built-in transports off, one UDPv4
# transport white-listed to 127.0.0.1, no shared memory, no data sharing; RustDDS: the node's
# ROS_LOCALHOST_ONLY=1 path), and the whole run is re-executed inside a private network namespace
# (unshare -n, only lo) when unshare is allowed. ROS_DOMAIN_ID 180-189 (TC_LATENCY_DOMAIN to move).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-10}"
rounds="${TC_LATENCY_ROUNDS:-1}"
only="${TC_LATENCY_ONLY:-cpp rust node}"
domain="${TC_LATENCY_DOMAIN:-180}"
mode="${TC_LATENCY_MODE:-interleave}"
slice="${TC_LATENCY_SLICE:-1}"
case $mode in interleave | sequential) ;; *) echo "run_latency.sh: TC_LATENCY_MODE is '$mode'; allowed: interleave, sequential" >&2; exit 2 ;; esac
export ROS_LOCALHOST_ONLY=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST

if [ -z "${TC_LATENCY_IN_NS:-}" ] && unshare -n true 2>/dev/null; then
    export TC_LATENCY_IN_NS=1
    # Builds first, outside (cargo may need nothing from the network, but keep it simple).
    python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
    export TC_PYTHON="$python"
    cargo build --release --locked --quiet --bin thickness_collision --example ros_relay
    bash tests/peers/fastdds/build.sh latency benches/latency/latency.cpp > /dev/null
    exec unshare -n bash -c 'ip link set lo up && exec bash "$0" "$@"' "$0" "$@"
fi
network="private network namespace (lo only)"
[ -n "${TC_LATENCY_IN_NS:-}" ] || network="host namespace, 127.0.0.1 only"

python="${TC_PYTHON:-$(bash scripts/setup_venv.sh | tail -n 1)}"
export TC_PYTHON="$python"
[ -n "${TC_LATENCY_IN_NS:-}" ] || cargo build --release --locked --quiet --bin thickness_collision --example ros_relay
peer=$(bash tests/peers/fastdds/build.sh latency benches/latency/latency.cpp)

pin_send=() pin_answer=()
if [ "${TC_LATENCY_PIN:-0}" = 1 ]; then
    pin_send=(taskset -c 0) pin_answer=(taskset -c 1)
fi

out=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done' EXIT

start() {  # start WHO DOMAIN: the answerer in the background, its pid in $pid
    case $1 in
        node) ROS_DOMAIN_ID=$2 "${pin_answer[@]}" target/release/thickness_collision run --params-file config/params.yaml > "$out/node-$2.log" 2>&1 & ;;
        node-handover) TC_CHECK_ON_RECEIVE=0 ROS_DOMAIN_ID=$2 "${pin_answer[@]}" target/release/thickness_collision run --params-file config/params.yaml > "$out/node-handover-$2.log" 2>&1 & ;;
        node-loop) TC_CHECK_ON_RECEIVE=0 RUSTDDS_DIRECT_SEND=0 ROS_DOMAIN_ID=$2 "${pin_answer[@]}" target/release/thickness_collision run --params-file config/params.yaml > "$out/node-loop-$2.log" 2>&1 & ;;
        rust) ROS_DOMAIN_ID=$2 "${pin_answer[@]}" target/release/examples/ros_relay relay > "$out/rust-$2.log" 2>&1 & ;;
        rust-loop) RUSTDDS_DIRECT_SEND=0 ROS_DOMAIN_ID=$2 "${pin_answer[@]}" target/release/examples/ros_relay relay > "$out/rust-loop-$2.log" 2>&1 & ;;
        cpp) "${pin_answer[@]}" "$peer" relay "$2" > "$out/cpp-$2.log" 2>&1 & ;;
    esac
    pid=$!
    pids+=("$pid")
}

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
for round in $(seq 1 "$rounds"); do
    if [ "$mode" = interleave ]; then
        # Every answerer up at once, each on its own domain; one sender feeds them in turn.
        started=() ds=()
        for who in $only; do
            start "$who" "$domain"
            started+=("$pid") ds+=("$domain:$who")
            domain=$(( domain + 1 ))
        done
        list=$(printf '%s\n' "${ds[@]}" | cut -d: -f1 | paste -sd,)
        "${pin_send[@]}" "$peer" interleave "$list" "$seconds" 1 "$slice" 1000 10000 > "$out/all-$round.jsonl"
        for dw in "${ds[@]}"; do
            grep "\"domain\": ${dw%%:*}," "$out/all-$round.jsonl" > "$out/${dw#*:}-$round.jsonl"
        done
        for p in "${started[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
        for p in "${started[@]}"; do wait "$p" 2>/dev/null || true; done
        continue
    fi
    for who in $only; do
        d=$domain
        domain=$(( domain + 1 ))
        start "$who" "$d"
        # One measuring participant for both rates (one that left without a word would keep a
        # RustDDS reliable writer waiting on it until its lease ends).
        "${pin_send[@]}" "$peer" measure "$d" "$seconds" 1 1000 10000 > "$out/$who-$round.jsonl"
        # The node prints its counts on SIGTERM.
        kill -TERM "$pid" 2>/dev/null || true
        wait "$pid" 2>/dev/null || true
    done
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

"$python" - "$out" "$rounds" "$only" "$seconds" "$load_before" "$load_after" "$network" "${TC_LATENCY_PIN:-0}" "$mode" "$slice" <<'PY'
import json, sys, pathlib
out, rounds, only, seconds, lb, la, network, pin, mode, slice_s = sys.argv[1:]
out = pathlib.Path(out)
names = {"node": "thickness_collision node", "rust": "Rust relay (ros2-client)", "cpp": "C++ relay (Fast DDS)",
         "node-loop": "node, handed over and sent by the event loop",
         "node-handover": "node, handed over to its loop", "rust-loop": "Rust relay, sent by the event loop"}
order = (f"answerers up together, fed in turn {slice_s} s at a time" if mode == "interleave" else "one answerer after the other")
print(f"{seconds} s per rate and answerer after 1 s of warm-up; {order}; {network}; load average before {lb}, after {la}; "
      f"{'sender on CPU 0, answerers on CPU 1' if pin == '1' else 'not pinned'}\n")
print("| rate | answerer | round | answered / sent | covered | median (µs) | p99 (µs) | p99.9 (µs) | max (µs) | late sends (> half a period) | check_seconds median / p99 (µs) |")
print("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
rows = {}
for rate in (1000, 10000):
    for r in range(1, int(rounds) + 1):
        for who in only.split():
            j = next(x for x in map(json.loads, (out / f"{who}-{r}.jsonl").read_text().splitlines()) if x["rate"] == rate)
            rows[(rate, who, r)] = j
            pc = 100.0 * j["answered"] / j["sent"]
            print(f"| {rate // 1000} kHz | {names[who]} | {r} | {j['answered']:,} / {j['sent']:,} ({pc:.2f} %) | {j['covered']:,} | "
                  + " | ".join(f"{j[k]:.0f}" if j[k] >= 0 else "-" for k in ("median_us", "p99_us", "p999_us", "max_us")) + f" | {j['late_sends']} | "
                  + (f"{j['check_median_us']:.0f} / {j['check_p99_us']:.0f}" if who.startswith("node") and j["check_median_us"] >= 0 else "-") + " |")
if "node" in only.split() and "cpp" in only.split():
    print()
    for r in range(1, int(rounds) + 1):
        n1, c1 = rows[(1000, "node", r)], rows[(1000, "cpp", r)]
        n10, c10 = rows[(10000, "node", r)], rows[(10000, "cpp", r)]
        ok1 = n1["answered"] == n1["sent"] and n1["p99_us"] - c1["p99_us"] <= 30 and n1["p999_us"] - c1["p999_us"] <= 100
        ok10 = n10["answered"] >= 0.999 * n10["sent"] and n10["p99_us"] - c10["p99_us"] <= 50
        print(f"round {r}: 1 kHz node - C++ relay: p99 {n1['p99_us'] - c1['p99_us']:+.0f} µs (goal <= 30), p99.9 "
              f"{n1['p999_us'] - c1['p999_us']:+.0f} µs (goal <= 100), {n1['sent'] - n1['answered']} unanswered (goal 0): "
              f"{'met' if ok1 else 'not met'}; 10 kHz: {100.0 * n10['answered'] / n10['sent']:.2f} % answered (goal >= 99.9), p99 "
              f"{n10['p99_us'] - c10['p99_us']:+.0f} µs (goal <= 50): {'met' if ok10 else 'not met'}")
for who in ("rust", "rust-loop", "node-loop", "node-handover"):
    if who in only.split() and "cpp" in only.split():
        for r in range(1, int(rounds) + 1):
            for rate in (1000, 10000):
                a, b = rows[(rate, who, r)], rows[(rate, "cpp", r)]
                print(f"round {r}, {rate // 1000} kHz: {names[who]} - C++ relay: median {a['median_us'] - b['median_us']:+.0f} µs, "
                      f"p99 {a['p99_us'] - b['p99_us']:+.0f} µs, p99.9 {a['p999_us'] - b['p999_us']:+.0f} µs")
PY
for f in "$out"/node-*.log; do  # node-loop-*.log, node-handover-*.log too
    [ -e "$f" ] && grep -h "shutting down" "$f" | sed "s/^/$(basename "$f" .log): /" || true
done
