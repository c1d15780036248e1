"""rosbag2 peer for tests/replay_bags.rs: writes input bags with rosbags, reads output bags back
with rosbags and with mcap-ros2-support, and parses the project's .msg/.srv files.

stdin: a JSON request with "op": "write" | "read" | "parse".
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
    for name in ["Contact", "CollisionReport"]:
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
        for m in req["messages"]:
            if "raw" in m:  # an undecodable message
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


def parse(req):
    out = {}
    for f in sorted((IFACE / "msg").glob("*.msg")):
        out[f"thickness_collision_msgs/msg/{f.stem}"] = sorted(get_types_from_msg(f.read_text(), f"thickness_collision_msgs/msg/{f.stem}"))
    for f in sorted((IFACE / "srv").glob("*.srv")):
        req_txt, resp_txt = f.read_text().split("---")
        out[f"thickness_collision_msgs/srv/{f.stem}_Request"] = sorted(get_types_from_msg(req_txt, f"thickness_collision_msgs/srv/{f.stem}_Request"))
        out[f"thickness_collision_msgs/srv/{f.stem}_Response"] = sorted(get_types_from_msg(resp_txt, f"thickness_collision_msgs/srv/{f.stem}_Response"))
    return out


req = json.load(sys.stdin)
json.dump({"write": write, "read": read, "parse": parse}[req["op"]](req), sys.stdout)
