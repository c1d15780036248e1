"""An independent ROS 2 participant (Cyclone DDS from Python) for tests/ros_node.rs.

Publishes sensor_msgs/JointState on rt/joint_states, reads rt/collisions with types built from the
project's own .msg files, and calls the check_states service (Cyclone's request/reply mapping).
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).

stdin: {"domain": id, "states": [{"name": [...], "position": [...], "stamp": ns}], "bad": [...],
        "service_states": [...], "timeout": s}
stdout: {"reports": [...], "service": [...]}
"""
import json
import sys
import time
import types
from dataclasses import dataclass
from pathlib import Path

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

ROOT = Path(__file__).resolve().parents[2]


def struct_typed(ros_type, fields):
    """An IDL struct named as ROS 2 names DDS types: pkg::msg::dds_::Type_."""
    pkg, kind, name = ros_type.split("/")
    cls = types.new_class(name, (IdlStruct,), {"typename": f"{pkg}::{kind}::dds_::{name}_"},
                          lambda ns: ns.update({"__annotations__": dict(fields)}))
    return dataclass(cls)


Time = struct_typed("builtin_interfaces/msg/Time", [("sec", t.int32), ("nanosec", t.uint32)])
Header = struct_typed("std_msgs/msg/Header", [("stamp", Time), ("frame_id", str)])
Point = struct_typed("geometry_msgs/msg/Point", [("x", t.float64), ("y", t.float64), ("z", t.float64)])
Vector3 = struct_typed("geometry_msgs/msg/Vector3", [("x", t.float64), ("y", t.float64), ("z", t.float64)])
JointState = struct_typed("sensor_msgs/msg/JointState", [("header", Header), ("name", t.sequence[str]), ("position", t.sequence[t.float64]),
                                                         ("velocity", t.sequence[t.float64]), ("effort", t.sequence[t.float64])])
Quaternion = struct_typed("geometry_msgs/msg/Quaternion", [("x", t.float64), ("y", t.float64), ("z", t.float64), ("w", t.float64)])
Transform = struct_typed("geometry_msgs/msg/Transform", [("translation", Vector3), ("rotation", Quaternion)])
TransformStamped = struct_typed("geometry_msgs/msg/TransformStamped", [("header", Header), ("child_frame_id", str), ("transform", Transform)])
TFMessage = struct_typed("tf2_msgs/msg/TFMessage", [("transforms", t.sequence[TransformStamped])])
KNOWN = {"std_msgs/Header": Header, "geometry_msgs/Point": Point, "geometry_msgs/Vector3": Vector3, "sensor_msgs/JointState": JointState}
PRIMS = {"string": str, "bool": bool, "uint32": t.uint32, "int32": t.int32, "float64": t.float64}


def from_msg(pkg, kind, name, text, local):
    """A Cyclone IDL struct from a .msg definition (the project's own files)."""
    fields = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        ty, fname = line.split()[:2]
        seq = ty.endswith("[]")
        ty = ty[:-2] if seq else ty
        py = PRIMS.get(ty) or KNOWN.get(ty) or local.get(ty)
        if py is None:
            raise ValueError(f"{name}.msg: unknown type {ty}")
        fields.append((fname, t.sequence[py] if seq else py))
    return struct_typed(f"{pkg}/{kind}/{name}", fields)


IFACE = ROOT / "interfaces" / "thickness_collision_msgs"
local = {}
local["Contact"] = from_msg("thickness_collision_msgs", "msg", "Contact", (IFACE / "msg/Contact.msg").read_text(), local)
local["CollisionReport"] = from_msg("thickness_collision_msgs", "msg", "CollisionReport", (IFACE / "msg/CollisionReport.msg").read_text(), local)
CollisionReport = local["CollisionReport"]
req_text, resp_text = (IFACE / "srv/CheckStates.srv").read_text().split("---")
# Cyclone's request/reply mapping puts a (guid, seq) header before the fields.
ReqBody = from_msg("thickness_collision_msgs", "srv", "CheckStates_Request", req_text, local)
RespBody = from_msg("thickness_collision_msgs", "srv", "CheckStates_Response", resp_text, local)
Request = struct_typed("thickness_collision_msgs/srv/CheckStates_Request", [("guid", t.uint64), ("seq", t.int64), ("states", t.sequence[JointState])])
Response = struct_typed("thickness_collision_msgs/srv/CheckStates_Response", [("guid", t.uint64), ("seq", t.int64), ("reports", t.sequence[CollisionReport])])


# rcl_interfaces, for the node's standard parameter services.
ParameterValue = struct_typed("rcl_interfaces/msg/ParameterValue", [
    ("type", t.uint8), ("bool_value", bool), ("integer_value", t.int64), ("double_value", t.float64), ("string_value", str),
    ("byte_array_value", t.sequence[t.uint8]), ("bool_array_value", t.sequence[bool]), ("integer_array_value", t.sequence[t.int64]),
    ("double_array_value", t.sequence[t.float64]), ("string_array_value", t.sequence[str])])
Parameter = struct_typed("rcl_interfaces/msg/Parameter", [("name", str), ("value", ParameterValue)])
SetParametersResult = struct_typed("rcl_interfaces/msg/SetParametersResult", [("successful", bool), ("reason", str)])
# ros2-client serves parameters with the "enhanced" RPC mapping (the request id travels as the
# sample identity, not in the payload), so these carry no (guid, seq) header.
GetReq = struct_typed("rcl_interfaces/srv/GetParameters_Request", [("names", t.sequence[str])])
GetResp = struct_typed("rcl_interfaces/srv/GetParameters_Response", [("values", t.sequence[ParameterValue])])
SetReq = struct_typed("rcl_interfaces/srv/SetParameters_Request", [("parameters", t.sequence[Parameter])])
SetResp = struct_typed("rcl_interfaces/srv/SetParameters_Response", [("results", t.sequence[SetParametersResult])])


def pv_double(x):
    return ParameterValue(type=3, bool_value=False, integer_value=0, double_value=float(x), string_value="", byte_array_value=[],
                          bool_array_value=[], integer_array_value=[], double_array_value=[], string_array_value=[])


def call(dp, service, req_type, resp_type, request, wait=15, make=None):
    """One service call. Matching is seen on our side before the node has matched us, and a
    request written in between is lost: so the request is sent again (with a fresh one from
    `make(k)` when given) after each second without an answer."""
    w = DataWriter(dp, Topic(dp, f"rq/{service}Request", req_type), qos=reliable)
    r = DataReader(dp, Topic(dp, f"rr/{service}Reply", resp_type), qos=reliable)
    end = time.time() + wait
    while (w.get_matched_subscriptions() == [] or r.get_matched_publications() == []) and time.time() < end:
        time.sleep(0.05)
    k = 0
    while time.time() < end:
        w.write(make(k) if make else request)
        k += 1
        resend = time.time() + 1.0
        while time.time() < min(resend, end):
            for x in r.take(N=10):
                return x
            time.sleep(0.01)
    return None


def js(s):
    ns = int(s.get("stamp", 0))
    return JointState(header=Header(stamp=Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000), frame_id=""),
                      name=s["name"], position=[float(x) for x in s["position"]], velocity=[], effort=[])


def report_json(r):
    return {"in_collision": bool(r.in_collision), "stamp": r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec, "frame_id": r.header.frame_id,
            "contacts": [{"link_name": c.link_name, "object_name": c.object_name, "triangle": int(c.triangle), "depth": c.depth,
                          "position": [c.position.x, c.position.y, c.position.z], "normal": [c.normal.x, c.normal.y, c.normal.z]} for c in r.contacts],
            "check_seconds": r.check_seconds}


req = json.load(sys.stdin)
dp = DomainParticipant(req["domain"])
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(1))
ns = req.get("ns", "")  # the node's namespace, e.g. "/robot1"
writer = DataWriter(dp, Topic(dp, f"rt{ns}/joint_states", JointState), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10)))
reader = DataReader(dp, Topic(dp, f"rt{ns}/collisions", CollisionReport), qos=reliable)
deadline = time.time() + req.get("timeout", 30)
# Wait for the node's reader and writer to match ours (with /tf input it reads no joint states).
while ((writer.get_matched_subscriptions() == [] and not req.get("tf_states")) or reader.get_matched_publications() == []) and time.time() < deadline:
    time.sleep(0.05)
out = {"matched": writer.get_matched_subscriptions() != [], "reports": [], "service": []}


def collect(n, wait):
    end = time.time() + wait
    got = []
    while len(got) < n and time.time() < end:
        for s in reader.take(N=100):
            got.append(report_json(s))
        time.sleep(0.005)
    return got


node = req.get("node")
if node and req.get("set_thickness") is not None:
    g = call(dp, f"{node}/get_parameters", GetReq, GetResp, GetReq(names=["default_thickness", "world_frame"]))
    out["get_before"] = None if g is None else [g.values[0].double_value, g.values[1].string_value]
    res = []
    for value in [-1.0, req["set_thickness"]]:  # a bad value first: refused, nothing changes
        sresp = call(dp, f"{node}/set_parameters", SetReq, SetResp, SetReq(parameters=[Parameter(name="default_thickness", value=pv_double(value))]))
        res.append(None if sresp is None else [bool(sresp.results[0].successful), sresp.results[0].reason])
    out["set_results"] = res
    g = call(dp, f"{node}/get_parameters", GetReq, GetResp, GetReq(names=["default_thickness"]))
    out["get_after"] = None if g is None else g.values[0].double_value

burst = req.get("burst", 0)
for k in range(burst):
    writer.write(js({"name": ["elbow_joint"], "position": [(k % 100) / 100.0], "stamp": k}))
if burst:
    time.sleep(1.0)
    collect(10 ** 9, 1.0)

# Warm-up: the node may not have matched our writer yet; send until a report comes back.
if req.get("states") or req.get("bad"):
    warm = {"name": ["elbow_joint"], "position": [0.0], "stamp": 1}
    end = time.time() + 15
    while time.time() < end and not collect(1, 0.5):
        writer.write(js(warm))
    collect(10 ** 9, 0.3)

for bad in req.get("bad", []):
    writer.write(js(bad))
    time.sleep(0.02)
collect(10 ** 9, 0.3)  # whatever the bad ones produced is not counted
for s in req["states"]:
    writer.write(js(s))
    got = collect(1, 5)
    out["reports"].extend(got)
if req.get("service_states"):
    sv = [js(s) for s in req["service_states"]]
    r = call(dp, f"{ns.strip('/') + '/' if ns else ''}check_states", Request, Response, None,
             make=lambda k: Request(guid=0x1234567890ABCDEF, seq=k + 1, states=sv))
    if r is not None:
        out["service"] = [report_json(x) for x in r.reports]
        out["service_seq"] = int(r.seq)
if req.get("tf_states"):
    tf_w = DataWriter(dp, Topic(dp, "rt/tf", TFMessage), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10)))
    end = time.time() + 15
    while tf_w.get_matched_subscriptions() == [] and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.3)
    out["tf_matched"] = tf_w.get_matched_subscriptions() != []
    out["tf_reports"] = []
    for st in req["tf_states"]:
        ns = int(st["stamp"])
        stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
        ts = [TransformStamped(header=Header(stamp=stamp, frame_id=x["parent"]), child_frame_id=x["child"],
                               transform=Transform(translation=Vector3(x=x["translation"][0], y=x["translation"][1], z=x["translation"][2]),
                                                   rotation=Quaternion(x=x["rotation"][0], y=x["rotation"][1], z=x["rotation"][2], w=x["rotation"][3])))
              for x in st["transforms"]]
        tf_w.write(TFMessage(transforms=ts))
        out["tf_reports"].extend(collect(1, 5))
json.dump(out, sys.stdout)
