"""One message sequence, two ways, for tests/one_pipeline.rs: sent live to the running node over
DDS by an independent ROS 2 participant (Cyclone DDS), or written into a rosbag2 bag by rosbags
with the same stamps, for `replay`.

stdin: {"op": "live", "domain": id, "ns": "", "messages": [...], "timeout": s}
       {"op": "bag", "path": dir, "storage": "mcap" | "sqlite3", "messages": [...]}
A message: {"topic": "/joint_states" | "/tf" | "/tf_static", "t": log time ns, "stamp": ns,
            (bags only: {"topic": "/robot_description", "t": ns, "data": urdf}),
            "name": [...], "position": [... numbers or "NaN"]} or {..., "transforms":
            [{"parent", "child", "translation": [x,y,z], "rotation": [x,y,z,w]}]}.
Live pacing: each message is sent after the previous one's report, or after 0.5 s for one that
gets none; a message with "burst": true is followed by the next at once (faster than the node
checks them). The first message must be a good state: it is sent again until a report comes back
(the node may not have matched our writer yet); its duplicates are dropped.
stdout (live): {"reports": [...], "diagnostics": {key: value}}; (bag): {"ok": true}.
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).
"""
import json
import os
import signal
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def num(x):
    return float("nan") if x == "NaN" else float(x)


def live(req):
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration
    import dds_types as T

    def stamp(ns):
        return T.Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)

    def tf(m):
        return T.TFMessage(transforms=[T.TransformStamped(
            header=T.Header(stamp=stamp(int(m["stamp"])), frame_id=x["parent"]), child_frame_id=x["child"],
            transform=T.Transform(translation=T.Vector3(x=num(x["translation"][0]), y=num(x["translation"][1]), z=num(x["translation"][2])),
                                  rotation=T.Quaternion(x=num(x["rotation"][0]), y=num(x["rotation"][1]), z=num(x["rotation"][2]), w=num(x["rotation"][3]))))
            for x in m["transforms"]])

    def js(m):
        return T.JointState(header=T.Header(stamp=stamp(int(m["stamp"])), frame_id=""), name=m["name"],
                            position=[num(x) for x in m["position"]], velocity=[], effort=[])

    dp = DomainParticipant(req["domain"])
    ns = req.get("ns", "")
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
    sensor = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10))
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(100))
    topics = {m["topic"] for m in req["messages"] if "topic" in m}
    writers = {}
    if "/joint_states" in topics:
        writers["/joint_states"] = (DataWriter(dp, Topic(dp, f"rt{ns}/joint_states", T.JointState), qos=sensor), js)
    if "/tf" in topics:
        writers["/tf"] = (DataWriter(dp, Topic(dp, "rt/tf", T.TFMessage), qos=sensor), tf)
    if "/tf_static" in topics:
        writers["/tf_static"] = (DataWriter(dp, Topic(dp, "rt/tf_static", T.TFMessage), qos=latched), tf)
    reader = DataReader(dp, Topic(dp, f"rt{ns}/collisions", T.CollisionReport), qos=reliable)
    diag_r = DataReader(dp, Topic(dp, "rt/diagnostics", T.DiagnosticArray), qos=reliable)
    deadline = time.time() + req.get("timeout", 30)
    while (any(w.get_matched_subscriptions() == [] for w, _ in writers.values()) or reader.get_matched_publications() == []
           or diag_r.get_matched_publications() == []) and time.time() < deadline:
        time.sleep(0.05)
    diagnostics = {}

    def drain_diag():
        for d in diag_r.take(N=100):
            for st in d.status:
                diagnostics.update({kv.key: kv.value for kv in st.values})

    def collect(wait, until=None):
        # `until`: a stamp; the reports keep being collected until one at or after it arrives
        # (the node has caught up), then as below.
        end = time.time() + wait
        got = []
        while time.time() < end:
            for r in reader.take(N=100):
                got.append({"stamp": r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec, "frame_id": r.header.frame_id,
                            "in_collision": bool(r.in_collision), "error": r.error, "motion": bool(r.motion), "fraction": r.fraction,
                            "contacts": [{"link_name": c.link_name, "object_name": c.object_name, "triangle": int(c.triangle), "depth": c.depth}
                                         for c in r.contacts]})
            if got and (until is None or any(g["stamp"] >= until for g in got)):
                # Anything else already on its way arrives within a few ms.
                end = min(end, time.time() + 0.05)
            time.sleep(0.005)
        return got

    def send(m):
        # {"signal": "STOP" or "CONT", "pid": n}: stop or resume a process (the node, to make it
        # fall behind the way a stalled machine does).
        if "signal" in m:
            os.kill(m["pid"], getattr(signal, "SIG" + m["signal"]))
            return
        w, make = writers[m["topic"]]
        w.write(make(m))

    reports = []
    first, rest = req["messages"][0], req["messages"][1:]
    end = time.time() + 20
    while time.time() < end:
        send(first)
        got = collect(0.5)
        if got:
            reports.append(got[0])
            break
    collect(0.3)  # the warm-up's duplicates
    for m in rest:
        send(m)
        if not m.get("burst"):
            reports.extend(collect(m.get("wait", 0.5), m.get("until")))
    time.sleep(1.5)  # a status after the last message
    drain_diag()
    return {"reports": reports, "diagnostics": diagnostics}


def bag(req):
    import numpy as np
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore
    store = get_typestore(Stores.ROS2_JAZZY)
    S = store.types
    plugin = StoragePlugin.MCAP if req["storage"] == "mcap" else StoragePlugin.SQLITE3

    def stamp(ns):
        return S["builtin_interfaces/msg/Time"](sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))

    def header(ns, frame):
        return S["std_msgs/msg/Header"](stamp=stamp(ns), frame_id=frame)

    with Writer(req["path"], version=8, storage_plugin=plugin) as w:
        conns = {}
        for m in req["messages"]:
            topic = m["topic"]
            if topic not in conns:
                ty = {"/joint_states": "sensor_msgs/msg/JointState", "/robot_description": "std_msgs/msg/String"}.get(topic, "tf2_msgs/msg/TFMessage")
                conns[topic] = w.add_connection(topic, ty, typestore=store)
            c = conns[topic]
            if topic == "/robot_description":
                msg = S["std_msgs/msg/String"](data=m["data"])
            elif topic == "/joint_states":
                msg = S["sensor_msgs/msg/JointState"](header=header(int(m["stamp"]), ""), name=m["name"],
                                                      position=np.array([num(x) for x in m["position"]], dtype=np.float64),
                                                      velocity=np.array([], dtype=np.float64), effort=np.array([], dtype=np.float64))
            else:
                msg = S["tf2_msgs/msg/TFMessage"](transforms=[S["geometry_msgs/msg/TransformStamped"](
                    header=header(int(m["stamp"]), x["parent"]), child_frame_id=x["child"],
                    transform=S["geometry_msgs/msg/Transform"](
                        translation=S["geometry_msgs/msg/Vector3"](x=num(x["translation"][0]), y=num(x["translation"][1]), z=num(x["translation"][2])),
                        rotation=S["geometry_msgs/msg/Quaternion"](x=num(x["rotation"][0]), y=num(x["rotation"][1]), z=num(x["rotation"][2]), w=num(x["rotation"][3]))))
                    for x in m["transforms"]])
            w.write(c, int(m["t"]), store.serialize_cdr(msg, c.msgtype))
    return {"ok": True}


req = json.load(sys.stdin)
json.dump({"live": live, "bag": bag}[req["op"]](req), sys.stdout)
