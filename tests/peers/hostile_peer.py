"""A hostile ROS 2 participant (Cyclone DDS from Python) for tests/node_robustness.rs.

Sends the node what an attacker, or a careless colleague, would: joint states that are NaN, a
million elements long, a 10,000-state burst, or bytes that are not a JointState; then
robot_descriptions that are deep, huge, point at special files or are not text at all (latched,
as robot_state_publisher offers them); a DATA_FRAG made by hand announcing a 3 GB sample. Then valid states (for the robot the node kept), a good
description and valid states for it; it returns their reports and the node's /diagnostics along
the way. Loopback only: the caller sets CYCLONEDDS_URI
(127.0.0.1, no multicast, peer 127.0.0.1), and runs the peer in the node's network namespace when
it has one.

stdin: {"domain": id, "timeout": s,
        "descriptions": [{"label": l, "text": t} | {"label": l, "deep": n} | {"label": l, "bytes": n}, each with
                         "expect": what the last one's refusal says],
        "raw_descriptions": n, "nan_states": n, "raw_states": n, "huge_state": n, "burst": n,
        "huge_datafrag": announced sample size of a hand-made DATA_FRAG, "node_pid": the node's pid,
        "states_kept": [{"name": [...], "position": [...], "stamp": ns}], "good_description": t, "states_good": [...]}
stdout: {"matched": bool, "sent": {...}, "largest_message": bytes, "diag_after_descriptions": status,
         "reports_kept": [...], "diag_after_good": status, "reports_good": [...], "diag_final": status, "seconds": {...}}
"""
import json
import struct
import sys
import time
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, str(Path(__file__).resolve().parent))

import dds_types as T  # noqa: E402

# The same DDS type names as the real messages, with bytes the sender chooses: the node sees a
# JointState or a String that does not decode. CDR lays a sequence<uint8> out as a string is laid
# out (a u32 length, then the bytes), which is what makes the raw String a non-UTF-8 one.
RawJointState = T.struct_typed("sensor_msgs/msg/JointState", [("blob", t.sequence[t.uint8])])
RawString = T.struct_typed("std_msgs/msg/String", [("blob", t.sequence[t.uint8])])

req = json.load(sys.stdin)
timeout = req.get("timeout", 30)
dp = DomainParticipant(req["domain"])
# A second participant for the raw types: one participant cannot hold two types on one topic.
dp_raw = DomainParticipant(req["domain"])
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
latched = Qos(Policy.Reliability.Reliable(duration(seconds=30)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
# The node reads joint_states best effort; reliable here costs nothing and paces large samples.
states_qos = Qos(Policy.Reliability.Reliable(duration(seconds=10)), Policy.History.KeepLast(10))

states_w = DataWriter(dp, Topic(dp, "rt/joint_states", T.JointState), qos=states_qos)
raw_states_w = DataWriter(dp_raw, Topic(dp_raw, "rt/joint_states", RawJointState), qos=states_qos)
desc_w = DataWriter(dp, Topic(dp, "rt/robot_description", T.String), qos=latched)
raw_desc_w = DataWriter(dp_raw, Topic(dp_raw, "rt/robot_description", RawString), qos=latched)
reports_r = DataReader(dp, Topic(dp, "rt/collisions", T.CollisionReport), qos=reliable)
diag_r = DataReader(dp, Topic(dp, "rt/diagnostics", T.DiagnosticArray), qos=reliable)

deadline = time.time() + timeout
writers = [states_w, raw_states_w, desc_w, raw_desc_w]
while time.time() < deadline and (any(w.get_matched_subscriptions() == [] for w in writers) or reports_r.get_matched_publications() == []
                                  or diag_r.get_matched_publications() == []):
    time.sleep(0.05)
out = {"matched": all(w.get_matched_subscriptions() != [] for w in writers) and reports_r.get_matched_publications() != [],
       "sent": {}, "seconds": {}, "phases": {}}
largest = 0
t_start = time.time()


def js(s):
    ns = int(s.get("stamp", 0))
    return T.JointState(header=T.Header(stamp=T.Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000), frame_id=""),
                        name=s["name"], position=[float(x) for x in s["position"]], velocity=[], effort=[])


def report_json(r):
    return {"in_collision": bool(r.in_collision), "stamp": r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec,
            "contacts": [{"link_name": c.link_name, "object_name": c.object_name, "depth": c.depth} for c in r.contacts],
            "error": r.error}


def drain_reports(wait):
    got = []
    end = time.time() + wait
    while time.time() < end:
        got.extend(report_json(s) for s in reports_r.take(N=1000))
        time.sleep(0.01)
    return got


def status_json(d):
    st = d.status[0]
    return {"level": int(st.level), "message": st.message, "values": {kv.key: kv.value for kv in st.values}}


def next_diagnostics(wait, want=None):
    """The first /diagnostics status published after now (that satisfies `want`, if given)."""
    diag_r.take(N=1000)
    end = time.time() + wait
    while time.time() < end:
        for d in diag_r.take(N=100):
            if d.status and (want is None or want(status_json(d))):
                return status_json(d)
        time.sleep(0.02)
    return None


def acked(w, seconds):
    """Whether the node acknowledged everything `w` wrote (cyclonedds 11.0.1 raises on a timeout)."""
    try:
        return bool(w.wait_for_acks(duration(seconds=seconds)))
    except Exception:  # noqa: BLE001 (its timeout path raises AttributeError)
        return False


def one_report(s, wait=10):
    """Sends a valid state until its report comes back (the node may still be busy)."""
    end = time.time() + wait
    while time.time() < end:
        states_w.write(js(s))
        for r in drain_reports(0.5):
            if r["stamp"] == int(s.get("stamp", 0)):
                return r
    return None


# Warm-up: a report for a valid state, so the node reads our writer before the hostile part.
warm = {"name": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"], "position": [0.0] * 7, "stamp": 1}  # the whole arm: missing_joint: last waits for it
out["warm_report"] = one_report(warm, 15) is not None
drain_reports(0.3)

# Hostile joint states.
sent = out["sent"]
t0 = time.time()
for k in range(req.get("nan_states", 0)):
    states_w.write(js({"name": ["elbow_joint", "wrist_1_joint"], "position": [float("nan"), 0.1], "stamp": 100 + k}))
    time.sleep(0.005)
sent["nan_states"] = req.get("nan_states", 0)
raw_blobs = [
    b"\xff" * 16,  # a frame_id of 4 GB
    struct.pack("<IIB3xI", 0, 1, 0, 1_000_000),  # a name sequence of 1,000,000 strings, none present
    struct.pack("<IIB3xIIB3xI", 0, 1, 0, 1, 2, ord("a"), 0x7fffffff),  # one name, then 2^31 positions claimed
]
for k in range(req.get("raw_states", 0)):
    raw_states_w.write(RawJointState(blob=list(raw_blobs[k % len(raw_blobs)])))
    time.sleep(0.02)
sent["raw_states"] = req.get("raw_states", 0)
n = req.get("huge_state", 0)
if n:
    # A million made-up names with a million positions, then a million positions for one name.
    names = [f"j{i}" for i in range(n)]
    huge = js({"name": names, "position": [0.5] * n, "stamp": 200})
    largest = max(largest, sum(4 + len(x) + 1 + 3 for x in names) + 8 * n)
    states_w.write(huge)
    del huge, names
    states_w.write(js({"name": ["elbow_joint"], "position": [0.25] * n, "stamp": 201}))
    largest = max(largest, 8 * n)
    sent["huge_states"] = 2
for k in range(req.get("burst", 0)):
    states_w.write(js({"name": ["elbow_joint"], "position": [(k % 100) / 100.0], "stamp": 1000 + k}))
sent["burst"] = req.get("burst", 0)
drain_reports(1.0)
out["seconds"]["states"] = time.time() - t0
out["phases"]["states"] = [t0, time.time()]
out["diag_after_states"] = next_diagnostics(3)

# Hostile descriptions, latched; each acknowledged by the node before the next is written.
t0 = time.time()
acked_labels = []
for d in req.get("descriptions", []):
    if "deep" in d:
        depth = int(d["deep"])
        text = "<robot name='deep'>" + "<a>" * depth + "</a>" * depth + "</robot>"
    elif "bytes" in d:
        body = "<link name='pad'/>"
        text = "<robot name='big'>" + body * (int(d["bytes"]) // len(body)) + "</robot>"
    else:
        text = d["text"]
    largest = max(largest, len(text.encode()))
    desc_w.write(T.String(data=text))
    del text
    if not acked(desc_w, 20):
        sent["not_acknowledged"] = d["label"]  # the node is gone or stuck: the rest is moot
        break
    acked_labels.append(d["label"])
for k in range(req.get("raw_descriptions", 0) if "not_acknowledged" not in sent else 0):
    raw_desc_w.write(RawString(blob=list(b"\xff\xfe<robot name='not utf-8'/>\x00")))
    acked(raw_desc_w, 10)
sent["descriptions"] = acked_labels
sent["raw_descriptions"] = req.get("raw_descriptions", 0)
out["seconds"]["descriptions"] = time.time() - t0

# A DATA_FRAG made by hand announcing a sample of `huge_datafrag` bytes (about 3 GB), sent over
# UDP to every port the node's process has open (found from /proc/<node_pid>: its sockets' inodes
# in /proc/<pid>/fd, their ports in /proc/<pid>/net/udp, the node's network namespace). RTPS header
# with our description writer's GUID prefix, INFO_TS, then DATA_FRAG from that writer (readerId
# unknown: the node hands it to every reader matched with the writer, the robot_description one)
# carrying fragment 1 of 1 KiB. Once more from a writer the node does not know (random GUID).
huge = int(req.get("huge_datafrag", 0))
if huge and req.get("node_pid"):
    import os
    import socket
    pid = int(req["node_pid"])
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            link = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if link.startswith("socket:["):
            inodes.add(link[8:-1])
    ports = sorted({int(f[1].split(":")[1], 16) for f in (ln.split() for ln in Path(f"/proc/{pid}/net/udp").read_text().splitlines()[1:])
                    if f[9] in inodes})

    def datafrag_message(guid16, sn, sample_size, frag_size=1024):
        now = time.time()
        header = b"RTPS" + bytes([2, 3, 0x01, 0x10]) + guid16[:12]
        info_ts = struct.pack("<BBHiI", 0x09, 0x01, 8, int(now), int((now % 1) * 2**32))
        payload = b"\x00\x01\x00\x00" + b"x" * (frag_size - 4)  # CDR_LE header, then the sample's first bytes
        body = struct.pack("<HH", 0, 28) + b"\x00\x00\x00\x00" + guid16[12:] + struct.pack("<iIIHHI", 0, sn, 1, 1, frag_size, sample_size) + payload
        return header + info_ts + struct.pack("<BBH", 0x16, 0x01, len(body)) + body

    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for guid in (desc_w.guid.bytes, os.urandom(12) + desc_w.guid.bytes[12:]):
        for sn in (1_000_000, 1_000_001):
            msg = datafrag_message(guid, sn, huge)
            for port in ports:
                udp.sendto(msg, ("127.0.0.1", port))
    udp.close()
    sent["huge_datafrag"] = {"sample_size": huge, "ports": ports, "datagrams": 4 * len(ports)}
    time.sleep(1.0)

# The node publishes /diagnostics every second from its loop: none in 3 s, it is gone or stuck.
out["diag_after_descriptions_any"] = next_diagnostics(3)
if "not_acknowledged" in sent or out["diag_after_descriptions_any"] is None:
    out["unresponsive_after_descriptions"] = True
    out["phases"]["descriptions"] = [t0, time.time()]
    out["largest_message"] = largest
    json.dump(out, sys.stdout)
    sys.exit(0)

# The node reads descriptions in order: wait for the status that shows the last text one refused
# (ERROR, `expect` in its message); the raw ones after it are read by the status after that.
expect = (req.get("descriptions") or [{}])[-1].get("expect", "")
out["diag_after_descriptions"] = next_diagnostics(10, lambda s: s["level"] == 2 and expect in s["message"])
out["diag_after_descriptions_next"] = next_diagnostics(3)

out["phases"]["descriptions"] = [t0, time.time()]
t0 = time.time()

# Valid states for the robot the node kept, then a good description and valid states for it.
drain_reports(0.3)
out["reports_kept"] = [one_report(s) for s in req.get("states_kept", [])]
if req.get("good_description"):
    desc_w.write(T.String(data=req["good_description"]))
    acked(desc_w, 10)
    out["diag_after_good"] = next_diagnostics(10, lambda s: s["level"] != 2)
drain_reports(0.3)
out["reports_good"] = [one_report(s) for s in req.get("states_good", [])]
out["diag_final"] = next_diagnostics(3)
out["phases"]["valid"] = [t0, time.time()]
out["largest_message"] = largest
out["seconds"]["total"] = time.time() - t_start
json.dump(out, sys.stdout)
