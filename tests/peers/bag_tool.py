"""rosbag2 peer for tests/replay_bags.rs: writes input bags with rosbags, reads output bags back
with rosbags and with mcap-ros2-support, and parses the project's .msg/.srv files.

stdin: a JSON request with "op": "write" | "read" | "view" | "parse". A "write" message is a
joint state ("name"), transforms ("transforms"), raw bytes ("raw") or a trajectory ("trajectory":
{"joint_names", "points": [{"positions", "velocities", "accelerations", "t"}]}, on
"trajectory_topic", default /joint_trajectory_controller/joint_trajectory).
"""
import json
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

ROOT = Path(__file__).resolve().parents[2]
IFACE = ROOT / "interfaces" / "thickness_collision_msgs"


def typestore_with_project_types():
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for name in ["Contact", "Clearance", "CollisionReport"]:
        types.update(get_types_from_msg((IFACE / "msg" / f"{name}.msg").read_text(), f"thickness_collision_msgs/msg/{name}"))
    store.register(types)
    return store


def time(ns, store):
    Time = store.types["builtin_interfaces/msg/Time"]
    return Time(sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))


def write(req):
    store = get_typestore(Stores.ROS2_JAZZY)
    plugin = StoragePlugin.MCAP if req["storage"] == "mcap" else StoragePlugin.SQLITE3
    Header = store.types["std_msgs/msg/Header"]
    JointState = store.types["sensor_msgs/msg/JointState"]
    TFMessage = store.types["tf2_msgs/msg/TFMessage"]
    TransformStamped = store.types["geometry_msgs/msg/TransformStamped"]
    Transform = store.types["geometry_msgs/msg/Transform"]
    Vector3 = store.types["geometry_msgs/msg/Vector3"]
    Quaternion = store.types["geometry_msgs/msg/Quaternion"]
    String = store.types["std_msgs/msg/String"]
    with Writer(req["path"], version=8, storage_plugin=plugin) as w:
        if req.get("robot_description") is not None:
            c = w.add_connection("/robot_description", "std_msgs/msg/String", typestore=store)
            w.write(c, req["messages"][0]["t"] - 1, store.serialize_cdr(String(data=req["robot_description"]), c.msgtype))
        js = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=store)
        tf = w.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=store)
        traj = None
        if any("trajectory" in m for m in req["messages"]):
            traj = w.add_connection(req.get("trajectory_topic", "/joint_trajectory_controller/joint_trajectory"),
                                    "trajectory_msgs/msg/JointTrajectory", typestore=store)
        for m in req["messages"]:
            if "trajectory" in m:  # a trajectory_msgs/JointTrajectory, points {positions, velocities, accelerations, t}
                JT = store.types["trajectory_msgs/msg/JointTrajectory"]
                JTP = store.types["trajectory_msgs/msg/JointTrajectoryPoint"]
                Duration = store.types["builtin_interfaces/msg/Duration"]
                arr = lambda xs: np.array(xs, dtype=np.float64)
                pts = [JTP(positions=arr(p["positions"]), velocities=arr(p.get("velocities", [])), accelerations=arr(p.get("accelerations", [])),
                           effort=arr([]), time_from_start=Duration(sec=int(p["t"] // 1_000_000_000), nanosec=int(p["t"] % 1_000_000_000)))
                       for p in m["trajectory"]["points"]]
                msg = JT(header=Header(stamp=time(0, store), frame_id=""), joint_names=m["trajectory"]["joint_names"], points=pts)
                w.write(traj, m["t"], store.serialize_cdr(msg, traj.msgtype))
            elif "raw" in m:  # an undecodable message
                w.write(js, m["t"], bytes(m["raw"]))
            elif "name" in m:
                msg = JointState(header=Header(stamp=time(m["stamp"], store), frame_id=""), name=m["name"],
                                 position=np.array(m["position"], dtype=np.float64),
                                 velocity=np.array([], dtype=np.float64), effort=np.array([], dtype=np.float64))
                w.write(js, m["t"], store.serialize_cdr(msg, js.msgtype))
            else:
                ts = [TransformStamped(header=Header(stamp=time(m["stamp"], store), frame_id=t["parent"]), child_frame_id=t["child"],
                                       transform=Transform(translation=Vector3(x=t["translation"][0], y=t["translation"][1], z=t["translation"][2]),
                                                           rotation=Quaternion(x=t["rotation"][0], y=t["rotation"][1], z=t["rotation"][2], w=t["rotation"][3])))
                      for t in m["transforms"]]
                w.write(tf, m["t"], store.serialize_cdr(TFMessage(transforms=ts), tf.msgtype))
    return {"ok": True}


def contacts(msg):
    return [{"link_name": c.link_name, "object_name": c.object_name, "triangle": int(c.triangle), "depth": float(c.depth),
             "position": [c.position.x, c.position.y, c.position.z], "normal": [c.normal.x, c.normal.y, c.normal.z]} for c in msg.contacts]


def read(req):
    store = typestore_with_project_types()
    out = {"rosbags": [], "mcap_ros2": []}
    with Reader(req["path"]) as r:
        conns = [c for c in r.connections if c.topic == "/collisions"]
        for conn, t, raw in r.messages(connections=conns):
            msg = store.deserialize_cdr(raw, conn.msgtype)
            out["rosbags"].append({"log_time": t, "type": conn.msgtype, "stamp": msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec,
                                   "frame_id": msg.header.frame_id, "in_collision": bool(msg.in_collision), "contacts": contacts(msg)})
    from mcap_ros2.reader import read_ros2_messages
    mcaps = sorted(Path(req["path"]).glob("*.mcap"))
    for f in mcaps:
        for m in read_ros2_messages(str(f), topics=["/collisions"]):
            msg = m.ros_msg
            out["mcap_ros2"].append({"log_time": m.log_time_ns, "schema": m.schema.name, "in_collision": bool(msg.in_collision), "contacts": contacts(msg)})
    return out


def view(req):
    """What a viewer gets from replay's output bag: every topic decoded with mcap-ros2-support
    (from the schemas in the file alone), and the topics and counts rosbags reads in metadata.yaml."""
    from mcap_ros2.reader import read_ros2_messages
    stamp = lambda s: s.sec * 1_000_000_000 + s.nanosec
    xyz = lambda p: [p.x, p.y, p.z]
    out = {"schemas": {}, "collisions": [], "contacts": [], "cells": [], "tf": [], "robot_description": []}
    for f in sorted(Path(req["path"]).glob("*.mcap")):
        for m in read_ros2_messages(str(f)):
            msg, topic = m.ros_msg, m.channel.topic
            out["schemas"][topic] = m.schema.name
            if topic == "/collisions":
                out["collisions"].append({"log_time": m.log_time_ns, "stamp": stamp(msg.header.stamp), "frame_id": msg.header.frame_id,
                                          "positions": [xyz(c.position) for c in msg.contacts], "normals": [xyz(c.normal) for c in msg.contacts],
                                          "depths": [c.depth for c in msg.contacts], "links": [c.link_name for c in msg.contacts],
                                          "objects": [c.object_name for c in msg.contacts]})
            elif topic in ("/collision_markers/contacts", "/collision_markers/cells"):
                markers = [{"ns": k.ns, "id": k.id, "type": k.type, "action": k.action, "frame_id": k.header.frame_id,
                            "stamp": stamp(k.header.stamp), "points": [xyz(p) for p in k.points] if topic.endswith("contacts") else len(k.points),
                            "colors": len(k.colors), "text": k.text} for k in msg.markers]
                out["contacts" if topic.endswith("contacts") else "cells"].append({"log_time": m.log_time_ns, "markers": markers})
            elif topic == "/tf":
                out["tf"].append({"log_time": m.log_time_ns, "transforms": [
                    {"parent": t.header.frame_id, "child": t.child_frame_id, "stamp": stamp(t.header.stamp),
                     "translation": xyz(t.transform.translation),
                     "rotation": [t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w]}
                    for t in msg.transforms]})
            elif topic == "/robot_description":
                out["robot_description"].append(msg.data)
    with Reader(req["path"]) as r:
        out["rosbags_topics"] = {c.topic: [c.msgtype, c.msgcount, c.ext.offered_qos_profiles != []] for c in r.connections}
    return out


def parse(req):
    out = {}
    for f in sorted((IFACE / "msg").glob("*.msg")):
        out[f"thickness_collision_msgs/msg/{f.stem}"] = sorted(get_types_from_msg(f.read_text(), f"thickness_collision_msgs/msg/{f.stem}"))
    for f in sorted((IFACE / "srv").glob("*.srv")):
        req_txt, resp_txt = f.read_text().split("---")
        out[f"thickness_collision_msgs/srv/{f.stem}_Request"] = sorted(get_types_from_msg(req_txt, f"thickness_collision_msgs/srv/{f.stem}_Request"))
        out[f"thickness_collision_msgs/srv/{f.stem}_Response"] = sorted(get_types_from_msg(resp_txt, f"thickness_collision_msgs/srv/{f.stem}_Response"))
    return out


def write_many(req):
    """Many joint states, generated here from a seed (JSON for a million states would be slow):
    uniform in [lo, hi] per joint. The CDR is packed by hand (the names never change, so only the
    stamp and the positions do) and checked once against rosbags' own serializer; the bag is written
    by rosbags' Writer. The joints: "urdf" (its moving joints) or "names", "lo", "hi". Optional
    "compression": "zstd" (MCAP chunks)."""
    import struct
    from rosbags.rosbag2 import CompressionFormat, CompressionMode
    store = get_typestore(Stores.ROS2_JAZZY)
    Header = store.types["std_msgs/msg/Header"]
    JointState = store.types["sensor_msgs/msg/JointState"]
    if "urdf" in req:  # the moving joints of a URDF, limits clamped to [-3, 3] (continuous: that range)
        import xml.etree.ElementTree as ET
        names, lo, hi = [], [], []
        for j in ET.parse(req["urdf"]).getroot().iter("joint"):
            if j.get("type") in ("revolute", "continuous", "prismatic"):
                lim = j.find("limit")
                a, b = (-3.0, 3.0) if lim is None or j.get("type") == "continuous" else (float(lim.get("lower", "-3")), float(lim.get("upper", "3")))
                names.append(j.get("name"))
                lo.append(max(a, -3.0))
                hi.append(min(b, 3.0))
    else:
        names, lo, hi = req["names"], req["lo"], req["hi"]
    lo, hi = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    n, t0, dt = int(req["count"]), int(req["t0"]), int(req.get("dt", 10_000_000))
    rng = np.random.default_rng(int(req.get("seed", 1)))

    def align(buf, k):  # CDR alignment, counted after the 4-byte encapsulation header
        buf += b"\0" * ((-(len(buf) - 4)) % k)

    head = bytearray(b"\x00\x01\x00\x00")
    head += b"\0" * 8  # stamp: sec, nanosec
    head += struct.pack("<I", 1) + b"\0"  # frame_id ""
    align(head, 4)
    head += struct.pack("<I", len(names))
    for name in names:
        align(head, 4)
        b = name.encode() + b"\0"
        head += struct.pack("<I", len(b)) + b
    align(head, 4)
    head += struct.pack("<I", len(names))
    align(head, 8)
    tail = bytearray()
    for _ in range(2):  # velocity, effort: empty
        pad = (-(len(head) + len(names) * 8 + len(tail) - 4)) % 4
        tail += b"\0" * pad + struct.pack("<I", 0)

    def cdr(k, pos):
        ns = t0 + k * dt
        head[4:12] = struct.pack("<iI", ns // 1_000_000_000, ns % 1_000_000_000)
        return bytes(head) + pos.tobytes() + bytes(tail)

    plugin = StoragePlugin.MCAP if req["storage"] == "mcap" else StoragePlugin.SQLITE3
    w = Writer(req["path"], version=8, storage_plugin=plugin)
    if req.get("compression") == "zstd":
        w.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with w:
        js = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=store)
        block = 65536
        for start in range(0, n, block):
            pos = lo + (hi - lo) * rng.random((min(block, n - start), len(names)))
            if start == 0:
                ns = t0
                ref = store.serialize_cdr(JointState(header=Header(stamp=time(ns, store), frame_id=""), name=names, position=pos[0],
                                                     velocity=np.array([], dtype=np.float64), effort=np.array([], dtype=np.float64)), js.msgtype)
                assert bytes(ref) == cdr(0, pos[0]), "hand-packed CDR differs from rosbags'"
            for i in range(len(pos)):
                k = start + i
                w.write(js, t0 + k * dt, cdr(k, pos[i]))
    return {"ok": True, "count": n}


req = json.load(sys.stdin)
json.dump({"write": write, "read": read, "view": view, "parse": parse, "write_many": write_many}[req["op"]](req), sys.stdout)
