"""Peers for tests/stuck_subscriber.rs (Cyclone DDS from Python): a reliable subscriber of
rt/collisions that the test freezes with SIGSTOP, and a publisher of joint states that reads the
reports while it is frozen.

stdin, first line: {"role": "stuck", "domain": id, "depth": n, "phase2_from": stamp}
  Subscribes to rt/collisions (reliable, keep last `depth`), prints {"first": stamp} once a
  report has arrived (the node has matched it), then takes reports; for each further line on
  stdin, and at its end (then exits), prints {"reports": n, "phase2": m} (m: reports stamped at
  or after phase2_from, i.e. published after it was resumed).
stdin: {"role": "warm", "domain": id, "stamp": ns}
  Sends one state (again every 0.2 s) until a report comes back; prints {"ok": bool}.
stdin: {"role": "flood", "domain": id, "count": n, "rate": hz, "base": stamp, "tail": s}
  Waits for a report (as warm), then sends `count` states stamped base + k at `rate`, taking the
  reports as they come, and `tail` seconds more; prints {"reports": n, "max_k": k, "after": {k0:
  n}, "seconds": s} ("after": how many reports are for states k >= k0, for a few k0).
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).
"""
import json
import select
import sys
import time
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, str(Path(__file__).resolve().parent))
import dds_types as T  # noqa: E402


def stamp_ns(r):
    return r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec


# Every actuated joint of the bundled arm: under missing_joint: last the node reports nothing until
# each has been received.
ARM = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"]


def js(k, ns):
    return T.JointState(header=T.Header(stamp=T.Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000), frame_id=""),
                        name=ARM, position=[0.0, 0.0, (k % 100) / 100.0, 0.0, 0.0, 0.0, 0.0], velocity=[], effort=[])


def say(obj):
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


req = json.loads(sys.stdin.readline())
dp = DomainParticipant(req["domain"])
role = req["role"]

if role == "stuck":
    reader = DataReader(dp, Topic(dp, "rt/collisions", T.CollisionReport),
                        qos=Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(req.get("depth", 5))))
    n, phase2, first = 0, 0, None
    while True:
        for r in reader.take(N=100):
            n += 1
            s = stamp_ns(r)
            phase2 += s >= req["phase2_from"]
            if first is None:
                first = s
                say({"first": s})
        ready, _, _ = select.select([sys.stdin], [], [], 0.005)
        if ready:
            line = sys.stdin.readline()
            say({"reports": n, "phase2": phase2})
            if not line:
                break
    sys.exit(0)

writer = DataWriter(dp, Topic(dp, "rt/joint_states", T.JointState), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10)))
reader = DataReader(dp, Topic(dp, "rt/collisions", T.CollisionReport),
                    qos=Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000)))


def warm(ns, wait=15):
    end = time.time() + wait
    while time.time() < end:
        writer.write(js(0, ns))
        resend = time.time() + 0.2
        while time.time() < resend:
            if reader.take(N=100):
                return True
            time.sleep(0.005)
    return False


if role == "warm":
    say({"ok": warm(req["stamp"])})
    sys.exit(0)

# flood
ok = warm(req["base"] - 1)
time.sleep(0.2)
reader.take(N=10_000)
base, count, period = req["base"], req["count"], 1.0 / req["rate"]
ks = []


def drain():
    for r in reader.take(N=1000):
        k = stamp_ns(r) - base
        if 0 <= k < count:
            ks.append(k)


start = time.perf_counter()
for k in range(count):
    due = start + k * period
    while True:
        now = time.perf_counter()
        if now >= due:
            break
        if due - now > 0.0003:
            time.sleep(0.0002)
    writer.write(js(k, base + k))
    if k % 8 == 0:
        drain()
sent = time.perf_counter() - start
end = time.time() + req.get("tail", 2.0)
while time.time() < end and (not ks or max(ks) < count - 1):
    drain()
    time.sleep(0.005)
drain()
say({"warm": ok, "reports": len(ks), "max_k": max(ks) if ks else -1, "seconds": round(sent, 2),
     "after": {str(k0): sum(1 for k in ks if k >= k0) for k0 in (8192, 10_000, 12_000, 14_000)}})
