"""The check_trajectory service called from an independent ROS 2 participant (Cyclone DDS from
Python), for tests/ros_trajectory.rs. Types from tests/peers/dds_types.py (the service's parts
built from the project's CheckTrajectory.srv), Cyclone's request/reply mapping.
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).

stdin: {"domain": id, "state": {"name", "position", "stamp"} (published first, until the node
        reports on it), "trajectories": [T...], "long": T (optional), "stream": [states sent in turn,
        every "period" s (default 0.05), while the long one is checked], "timeout": s}
        T = {"joint_names": [...], "points": [{"positions": [...], "velocities": [...] (optional),
        "accelerations": [...] (optional), "t": ns}], "interpolation": "" (default) or "linear",
        "path_tolerance": [...] (optional)}; a position may be the string "NaN".
stdout: {"state_report": report or null, "answers": [A...], "long": {"answer": A, "seconds": s,
        "reports_before_answer": n, "states_sent": n, "max_report_gap": s,
        "max_latency": s (a report after the sending of the state it is stamped with), "latencies": n}}
        A = {"valid", "segment", "fraction", "time_from_start": ns, "contacts": [...], "error"}
"""
import json
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
import dds_types as d  # noqa: E402
import service_client  # noqa: E402

req = json.load(sys.stdin)
dp = DomainParticipant(req["domain"])
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
timeout = req.get("timeout", 60)
GUID = 0x0123456789ABCDEF


def stamp(ns):
    return d.Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def js(s):
    return d.JointState(header=d.Header(stamp=stamp(int(s.get("stamp", 0))), frame_id=""), name=s["name"],
                        position=[float(x) for x in s["position"]], velocity=[], effort=[])


def trajectory(tr):
    points = [d.JointTrajectoryPoint(positions=[float(x) for x in p["positions"]], velocities=[float(x) for x in p.get("velocities", [])],
                                     accelerations=[float(x) for x in p.get("accelerations", [])], effort=[],
                                     time_from_start=d.DurationMsg(sec=int(p["t"]) // 1_000_000_000, nanosec=int(p["t"]) % 1_000_000_000))
              for p in tr["points"]]
    return d.JointTrajectory(header=d.Header(stamp=stamp(0), frame_id="world"), joint_names=tr["joint_names"], points=points)


def answer_json(r):
    return {"valid": bool(r.valid), "segment": int(r.segment), "fraction": r.fraction,
            "time_from_start": r.time_from_start.sec * 1_000_000_000 + r.time_from_start.nanosec,
            "contacts": [{"link_name": c.link_name, "object_name": c.object_name, "triangle": int(c.triangle), "depth": c.depth,
                          "position": [c.position.x, c.position.y, c.position.z], "normal": [c.normal.x, c.normal.y, c.normal.z]}
                         for c in r.contacts],
            "error": r.error}


def report_json(r):
    return {"in_collision": bool(r.in_collision), "stamp": r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec,
            "contacts": len(r.contacts), "error": r.error}


ns = req.get("ns", "")
states_w = DataWriter(dp, Topic(dp, f"rt{ns}/joint_states", d.JointState), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10)))
reports_r = DataReader(dp, Topic(dp, f"rt{ns}/collisions", d.CollisionReport), qos=reliable)
svc = f"{ns.strip('/') + '/' if ns else ''}check_trajectory"
req_w = DataWriter(dp, Topic(dp, f"rq/{svc}Request", d.TrajRequest), qos=reliable)
resp_r = DataReader(dp, Topic(dp, f"rr/{svc}Reply", d.TrajResponse), qos=reliable)
end = time.time() + timeout
while (states_w.get_matched_subscriptions() == [] or reports_r.get_matched_publications() == [] or req_w.get_matched_subscriptions() == []
       or resp_r.get_matched_publications() == []) and time.time() < end:
    time.sleep(0.05)
out = {"state_report": None, "answers": [], "long": None}
client = service_client.Client(req_w, resp_r, lambda tr, seq: d.TrajRequest(
    guid=GUID, seq=seq, trajectory=trajectory(tr), interpolation=tr.get("interpolation", ""),
    path_tolerance=[float(x) for x in tr.get("path_tolerance", [])]))
send, wait_answer = client.send, client.wait_answer


# Warm-up: a request written before the node matched us is lost, so a refused request (answered
# at once) is sent until one is answered; after that every request is written once.
empty = {"joint_names": [], "points": []}
while time.time() < end:
    if wait_answer(send(empty), 1.0) is not None:
        break

# The state the node merges trajectories with: sent until the node reports on it.
if req.get("state"):
    st = req["state"]
    while time.time() < end and out["state_report"] is None:
        states_w.write(js(st))
        stop = time.time() + 0.5
        while time.time() < stop and out["state_report"] is None:
            for r in reports_r.take(N=100):
                if r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec == int(st["stamp"]):
                    out["state_report"] = report_json(r)
            time.sleep(0.01)

for tr in req.get("trajectories", []):
    r = wait_answer(send(tr), max(1.0, end - time.time()))
    out["answers"].append(None if r is None else answer_json(r))

# A long trajectory, and the live stream while it is checked: each report's latency (from the
# sending of the state it is stamped with), measured from when the request has been written.
if req.get("long"):
    reports_r.take(N=1000)
    k = send(req["long"])
    t0 = time.time()
    answer, answered_at, arrivals, latencies, sent_at = None, None, [], [], {}
    stream = req.get("stream", [])
    period = float(req.get("period", 0.05))
    i = 0
    while time.time() < end and answer is None:
        if stream:
            # Cycled, stamped `period` apart from the first one's stamp.
            st = dict(stream[i % len(stream)], stamp=int(stream[0]["stamp"]) + int(period * 1e9) * i)
            sent_at[st["stamp"]] = time.time()
            states_w.write(js(st))
            i += 1
        stop = time.time() + period
        while time.time() < stop and answer is None:
            for r in reports_r.take(N=100):
                now = time.time()
                arrivals.append(now - t0)
                sent = sent_at.get(r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec)
                if sent is not None:
                    latencies.append(now - sent)
            for x in resp_r.take(N=10):
                if int(x.seq) == k:
                    answer, answered_at = x, time.time() - t0
            time.sleep(0.002)
    gaps = [b - a for a, b in zip(arrivals, arrivals[1:])]
    out["long"] = {"answer": None if answer is None else answer_json(answer), "seconds": answered_at,
                   "reports_before_answer": len(arrivals), "states_sent": i, "max_report_gap": max(gaps) if gaps else None,
                   "max_latency": max(latencies) if latencies else None, "latencies": len(latencies)}
json.dump(out, sys.stdout)
