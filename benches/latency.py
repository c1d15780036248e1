"""Latency of the node beside a trivial Python relay, measured by the same Cyclone DDS peer.

The peer publishes sensor_msgs/JointState on rt/joint_states at 1 kHz (stamp = send time) and
reads rt/collisions; latency = receive time - stamp. The relay (started with --relay) answers each
JointState with an empty CollisionReport carrying the same stamp: the cost of DDS and Python alone.

  python benches/latency.py --relay --domain D            # the relay
  python benches/latency.py --domain D --count 5000       # the measuring peer; prints JSON
Loopback only: CYCLONEDDS_URI must point at a 127.0.0.1-only configuration.
"""
import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "peers"))
import importlib.util

spec = importlib.util.spec_from_file_location("peer_types", Path(__file__).resolve().parents[1] / "tests" / "peers" / "dds_types.py")
T = importlib.util.module_from_spec(spec)
spec.loader.exec_module(T)

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

ap = argparse.ArgumentParser()
ap.add_argument("--domain", type=int, required=True)
ap.add_argument("--relay", action="store_true")
ap.add_argument("--count", type=int, default=5000)
ap.add_argument("--rate", type=float, default=1000.0)
a = ap.parse_args()
dp = DomainParticipant(a.domain)
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10))

if a.relay:
    r = DataReader(dp, Topic(dp, "rt/joint_states", T.JointState), qos=best_effort)
    w = DataWriter(dp, Topic(dp, "rt/collisions", T.CollisionReport), qos=reliable)
    print("relay ready", flush=True)
    while True:
        for s in r.take(N=100):
            w.write(T.CollisionReport(header=T.Header(stamp=s.header.stamp, frame_id="world"), in_collision=False, contacts=[], check_seconds=0.0))
        time.sleep(0.0002)

w = DataWriter(dp, Topic(dp, "rt/joint_states", T.JointState), qos=best_effort)
r = DataReader(dp, Topic(dp, "rt/collisions", T.CollisionReport), qos=reliable)
end = time.time() + 20
while (w.get_matched_subscriptions() == [] or r.get_matched_publications() == []) and time.time() < end:
    time.sleep(0.05)
time.sleep(1.0)
names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"]
lat, check = [], []
period = 1.0 / a.rate
t_next = time.perf_counter()
for k in range(a.count):
    ns = time.time_ns()
    x = k * 0.001
    pos = [0.8 * (x % 3.0) - 1.2, 0.3 + 0.9 * ((x * 0.7) % 1.0), 0.5, 0.1, 0.2, 0.0, 0.02]
    w.write(T.JointState(header=T.Header(stamp=T.Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000), frame_id=""),
                         name=names, position=pos, velocity=[], effort=[]))
    for s in r.take(N=100):
        now = time.time_ns()
        lat.append((now - (s.header.stamp.sec * 1_000_000_000 + s.header.stamp.nanosec)) / 1e6)
        check.append(s.check_seconds * 1e3)
    t_next += period
    while time.perf_counter() < t_next:
        pass
end = time.time() + 1.0
while time.time() < end:
    for s in r.take(N=100):
        now = time.time_ns()
        lat.append((now - (s.header.stamp.sec * 1_000_000_000 + s.header.stamp.nanosec)) / 1e6)
        check.append(s.check_seconds * 1e3)
    time.sleep(0.001)


def pct(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p / 100 * len(v)))] if v else float("nan")


print(json.dumps({"sent": a.count, "received": len(lat), "latency_ms": {"median": statistics.median(lat) if lat else None, "p99": pct(lat, 99)},
                  "check_ms": {"median": statistics.median(check) if check else None, "p99": pct(check, 99)}}))
