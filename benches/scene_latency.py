#!/usr/bin/env python3
"""Joint-state latency while the planning scene changes: a Cyclone DDS peer (types parsed from
moveit_msgs' own files, tests/peers/msg_idl.py) streams the bundled arm's state at RATE Hz to a
running node for 2 x SECONDS; in the second half it also adds and removes a TRIANGLES-triangle
thin sheet on `collision_object` at 10 Hz (ADD of fresh geometry, then REMOVE). Each state's
latency is the report's arrival minus the state's send, both on this host's clock; the table gives
median, p99 and max per phase, and how many states were answered. Run by
benches/run_scene_latency.sh (which starts the node); loopback only (CYCLONEDDS_URI).

    python benches/scene_latency.py DOMAIN [--rate 1000] [--seconds 5] [--triangles 10000]
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "peers"))
import dds_types  # noqa: E402
import msg_idl  # noqa: E402
from cyclonedds.core import Policy, Qos  # noqa: E402
from cyclonedds.domain import DomainParticipant  # noqa: E402
from cyclonedds.pub import DataWriter  # noqa: E402
from cyclonedds.sub import DataReader  # noqa: E402
from cyclonedds.topic import Topic  # noqa: E402
from cyclonedds.util import duration  # noqa: E402

ARM = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"]


def sheet(triangles, k):
    """A flat square sheet of about `triangles` triangles 0.6 m above the table, shifted by k mm (new geometry each time)."""
    n = max(1, int((triangles / 2) ** 0.5))
    h = 1.0 / n
    verts = [{"x": i * h - 0.5, "y": j * h - 0.5, "z": 0.6 + 0.001 * k} for i in range(n + 1) for j in range(n + 1)]
    tris = []
    for i in range(n):
        for j in range(n):
            a = i * (n + 1) + j
            tris.append({"vertex_indices": [a, a + n + 1, a + n + 2]})
            tris.append({"vertex_indices": [a, a + n + 2, a + 1]})
    return {"vertices": verts, "triangles": tris}


def scene_traffic(args):
    """ADD of fresh geometry and REMOVE alternating every 50 ms (each at 10 Hz) on collision_object."""
    dp = DomainParticipant(args.domain)
    scene_qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile, Policy.History.KeepLast(10))
    co_w = DataWriter(dp, Topic(dp, "rt/collision_object", msg_idl.idl("moveit_msgs/msg/CollisionObject")), qos=scene_qos)
    pose = {"position": {"x": 0.0, "y": 0.0, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}
    adds = [msg_idl.from_json("moveit_msgs/msg/CollisionObject", {"header": {"frame_id": "world"}, "id": "sheet", "pose": pose,
                                                                  "meshes": [sheet(args.triangles, k)], "operation": 0}) for k in range(4)]
    remove = msg_idl.from_json("moveit_msgs/msg/CollisionObject", {"header": {"frame_id": "world"}, "id": "sheet", "operation": 1})
    end = time.time() + 30
    while co_w.get_matched_subscriptions() == [] and time.time() < end:
        time.sleep(0.05)
    print("ready", flush=True)
    t_end, k, next_scene = time.time() + args.seconds, 0, time.time()
    while time.time() < t_end:
        if time.time() >= next_scene:
            co_w.write(adds[(k // 2) % len(adds)] if k % 2 == 0 else remove)
            k += 1
            next_scene += 0.05
        time.sleep(0.001)


def apply_timing(args):
    """apply_planning_scene with an ADD of a sheet of about args.apply triangles (fresh geometry each
    time), request written to reply taken, 5 times; a REMOVE applied between (also timed)."""
    import service_client
    dp = DomainParticipant(args.domain)
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100))
    Req, Resp = msg_idl.cyclone_service("moveit_msgs/srv/ApplyPlanningScene")
    w = DataWriter(dp, Topic(dp, "rq/apply_planning_sceneRequest", Req), qos=reliable)
    r = DataReader(dp, Topic(dp, "rr/apply_planning_sceneReply", Resp), qos=reliable)
    scenes = []
    pose = {"position": {"x": 0.0, "y": 0.0, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}
    for k in range(5):
        add = {"header": {"frame_id": "world"}, "id": "sheet", "pose": pose, "meshes": [sheet(args.apply, k)], "operation": 0}
        scenes.append(msg_idl.from_json("moveit_msgs/msg/PlanningScene", {"is_diff": True, "world": {"collision_objects": [add]}}))
    remove = msg_idl.from_json("moveit_msgs/msg/PlanningScene",
                               {"is_diff": True, "world": {"collision_objects": [{"header": {"frame_id": "world"}, "id": "sheet", "operation": 1}]}})
    client = service_client.Client(w, r, lambda scene, seq: Req(guid=0x5C3E7E0A11CE0002, seq=seq, scene=scene))
    end = time.time() + 30
    while (w.get_matched_subscriptions() == [] or r.get_matched_publications() == []) and time.time() < end:
        time.sleep(0.05)
    client.wait_answer(client.send(remove), 5.0)  # warm-up (and a clean scene)
    times, removes = [], []
    for scene in scenes:
        t = time.time()
        a = client.wait_answer(client.send(scene), 30.0)
        times.append(time.time() - t)
        assert a is not None and a.success, "apply_planning_scene failed"
        t = time.time()
        client.wait_answer(client.send(remove), 30.0)
        removes.append(time.time() - t)
    n = len(sheet(args.apply, 0)["triangles"])
    print(f"apply_planning_scene ADD of a {n:,}-triangle sheet, request to reply: median {percentile(times, 0.5) * 1e3:.1f} ms "
          f"(runs {', '.join(f'{x * 1e3:.0f}' for x in times)} ms); REMOVE: median {percentile(removes, 0.5) * 1e3:.1f} ms")
    print("SCENE_APPLY " + json.dumps({"triangles": n, "add_s": times, "remove_s": removes}))


def take_reports(reports, sent, got):
    """The reports waiting: the arrival time of each sent state's first one into `got`."""
    for r in reports.take(N=1000):
        if hasattr(r, "header"):
            st = r.header.stamp.sec * 10**9 + r.header.stamp.nanosec
            if st in sent and st not in got:
                got[st] = time.time()


def percentile(xs, q):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(q * len(xs)))] if xs else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("domain", type=int)
    ap.add_argument("--rate", type=float, default=1000.0)
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--triangles", type=int, default=10000)
    ap.add_argument("--scene-only", action="store_true", help="(internal) publish the scene traffic for --seconds, from a process of its own")
    ap.add_argument("--apply", type=int, default=0, metavar="TRIANGLES",
                    help="instead: apply_planning_scene of a sheet of about TRIANGLES triangles, request to reply, 5 times (REMOVE between)")
    args = ap.parse_args()
    if args.scene_only:
        return scene_traffic(args)
    if args.apply:
        return apply_timing(args)
    dp = DomainParticipant(args.domain)
    sensor = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(100))
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10000))
    JointState = msg_idl.idl("sensor_msgs/msg/JointState")
    js_w = DataWriter(dp, Topic(dp, "rt/joint_states", JointState), qos=sensor)
    reports = DataReader(dp, Topic(dp, "rt/collisions", dds_types.CollisionReport), qos=reliable)
    end = time.time() + 30
    while (js_w.get_matched_subscriptions() == [] or reports.get_matched_publications() == []) and time.time() < end:
        time.sleep(0.05)
    position = [0.1, -1.2, 1.0, 0.0, 0.5, 0.0, 0.01]
    sent, got = {}, {}
    stamp = 1_000_000_000
    period = 1.0 / args.rate
    phases = {}
    for phase in ("quiet", "scene"):
        # The scene traffic from a process of its own: serialising a large message in this one
        # would stall the sender and the timing of the reports.
        traffic = None
        if phase == "scene":
            traffic = subprocess.Popen([sys.executable, __file__, str(args.domain), "--scene-only", "--seconds", str(args.seconds + 1),
                                        "--triangles", str(args.triangles)], stdout=subprocess.PIPE)
            assert traffic.stdout.readline().strip() == b"ready"
        t_end = time.time() + args.seconds
        next_state = time.time()
        first = stamp
        while time.time() < t_end:
            now = time.time()
            if now >= next_state:
                js_w.write(JointState(header=msg_idl.from_json("std_msgs/msg/Header", {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9}}),
                                      name=ARM, position=position, velocity=[], effort=[]))
                sent[stamp] = time.time()
                stamp += 1000
                next_state += period
            take_reports(reports, sent, got)
            time.sleep(0)
        phases[phase] = (first, stamp)
        if traffic is not None:
            traffic.wait()
    drain = time.time() + 1.0
    while time.time() < drain:
        take_reports(reports, sent, got)
        time.sleep(0.001)
    out = {}
    print(f"| phase ({args.rate:.0f} Hz, {args.seconds:.0f} s) | answered | median ms | p99 ms | max ms |")
    print("|---|---:|---:|---:|---:|")
    for phase, (a, b) in phases.items():
        lat = [(got[s] - sent[s]) * 1e3 for s in range(a, b, 1000) if s in got]
        n = len(range(a, b, 1000))
        out[phase] = {"sent": n, "answered": len(lat), "median_ms": percentile(lat, 0.5), "p99_ms": percentile(lat, 0.99), "max_ms": max(lat, default=float("nan"))}
        name = "quiet" if phase == "quiet" else f"{args.triangles:,}-triangle sheet added/removed at 10 Hz"
        print(f"| {name} | {len(lat)} of {n} | {out[phase]['median_ms']:.2f} | {out[phase]['p99_ms']:.2f} | {out[phase]['max_ms']:.2f} |")
    print("SCENE_LATENCY " + json.dumps(out))


if __name__ == "__main__":
    main()
