"""An independent ROS 2 participant (Cyclone DDS from Python) for tests/ros_node.rs.

Publishes sensor_msgs/JointState on rt/joint_states, reads rt/collisions with types built from the
project's own .msg files, and calls the check_states service (Cyclone's request/reply mapping).
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).

stdin: {"domain": id, "states": [{"name": [...], "position": [...], "stamp": ns}], "bad": [...],
        "service_states": [...], "timeout": s, "warmup": s (15), "service_wait": s (15)}
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

sys.path.insert(0, str(Path(__file__).resolve().parent))


from dds_types import *  # noqa: F401,F403 (the IDL types)
import dds_types as _types
t = _types.t


def pv_double(x):
    return ParameterValue(type=3, bool_value=False, integer_value=0, double_value=float(x), string_value="", byte_array_value=[],
                          bool_array_value=[], integer_array_value=[], double_array_value=[], string_array_value=[])


def call(dp, service, req_type, resp_type, request, wait=None, make=None):
    """One service call. Matching is seen on our side before the node has matched us, and a
    request written in between is lost: so the request is sent again (with a fresh one from
    `make(k)` when given) after each second without an answer."""
    w = DataWriter(dp, Topic(dp, f"rq/{service}Request", req_type), qos=reliable)
    r = DataReader(dp, Topic(dp, f"rr/{service}Reply", resp_type), qos=reliable)
    end = time.time() + (req.get("service_wait", 15) if wait is None else wait)
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


# Every actuated joint of the bundled arm (missing_joint: last waits for all of them).
ARM = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"]


def js(s):
    ns = int(s.get("stamp", 0))
    return JointState(header=Header(stamp=Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000), frame_id=""),
                      name=s["name"], position=[float(x) for x in s["position"]], velocity=[], effort=[])


def report_json(r):
    return {"in_collision": bool(r.in_collision), "stamp": r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec, "frame_id": r.header.frame_id,
            "contacts": [{"link_name": c.link_name, "object_name": c.object_name, "triangle": int(c.triangle), "depth": c.depth,
                          "position": [c.position.x, c.position.y, c.position.z], "normal": [c.normal.x, c.normal.y, c.normal.z]} for c in r.contacts],
            "check_seconds": r.check_seconds, "error": r.error}


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
    # The parameter services follow the node's service_mapping (cyclone by default): Cyclone's
    # (guid, seq) header before the fields, as `ros2 param` on rmw_cyclonedds_cpp sends it.
    if req.get("service_mapping") == "enhanced":
        pget = lambda names: call(dp, f"{node}/get_parameters", GetReq, GetResp, GetReq(names=names))  # noqa: E731
        pset = lambda ps: call(dp, f"{node}/set_parameters", SetReq, SetResp, SetReq(parameters=ps))  # noqa: E731
    else:
        GetReqCy, GetRespCy = (_types._with_header(f"rcl_interfaces/srv/GetParameters_{k}", c) for k, c in (("Request", GetReq), ("Response", GetResp)))
        SetReqCy, SetRespCy = (_types._with_header(f"rcl_interfaces/srv/SetParameters_{k}", c) for k, c in (("Request", SetReq), ("Response", SetResp)))
        pget = lambda names: call(dp, f"{node}/get_parameters", GetReqCy, GetRespCy, None,  # noqa: E731
                                  make=lambda k: GetReqCy(guid=0x5EED, seq=k + 1, names=names))
        pset = lambda ps: call(dp, f"{node}/set_parameters", SetReqCy, SetRespCy, None,  # noqa: E731
                               make=lambda k: SetReqCy(guid=0x5EED, seq=k + 1, parameters=ps))
    g = pget(["default_thickness", "world_frame"])
    out["get_before"] = None if g is None else [g.values[0].double_value, g.values[1].string_value]
    res = []
    for value in [-1.0, req["set_thickness"]]:  # a bad value first: refused, nothing changes
        sresp = pset([Parameter(name="default_thickness", value=pv_double(value))])
        res.append(None if sresp is None else [bool(sresp.results[0].successful), sresp.results[0].reason])
    out["set_results"] = res
    g = pget(["default_thickness"])
    out["get_after"] = None if g is None else g.values[0].double_value

if req.get("robot_descriptions"):
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
    dw = DataWriter(dp, Topic(dp, f"rt{ns}/robot_description", _types.String), qos=latched)
    end = time.time() + 15
    while dw.get_matched_subscriptions() == [] and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.5)
    for text in req["robot_descriptions"]:
        dw.write(_types.String(data=text))
        time.sleep(1.0)  # the node rebuilds its model
    out["description_matched"] = dw.get_matched_subscriptions() != []

burst = req.get("burst", 0)
for k in range(burst):
    writer.write(js({"name": ARM, "position": [0.0, 0.0, (k % 100) / 100.0, 0.0, 0.0, 0.0, 0.0], "stamp": k}))
if burst:
    time.sleep(1.0)
    collect(10 ** 9, 1.0)

# Warm-up: the node may not have matched our writer yet; send until a report comes back.
if req.get("states") or req.get("bad"):
    warm = {"name": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"], "position": [0.0] * 7, "stamp": 1}  # the whole arm: missing_joint: last waits for it
    end = time.time() + req.get("warmup", 15)
    while time.time() < end and not collect(1, 0.5):
        writer.write(js(warm))
    collect(10 ** 9, 0.3)

contacts_r = None
if req.get("markers"):
    contacts_r = DataReader(dp, Topic(dp, f"rt{ns}/collision_markers/contacts", _types.MarkerArray), qos=reliable)
    end = time.time() + 10
    while contacts_r.get_matched_publications() == [] and time.time() < end:
        time.sleep(0.05)
    contacts_r.take(N=1000)
t_states = time.time()

for bad in req.get("bad", []):
    writer.write(js(bad))
    time.sleep(0.02)
collect(10 ** 9, 0.3)  # whatever the bad ones produced is not counted
for s in req["states"]:
    writer.write(js(s))
    got = collect(1, 5)
    out["reports"].extend(got)
if contacts_r is not None:
    out["states_seconds"] = time.time() - t_states
    time.sleep(0.3)
    msgs = contacts_r.take(N=1000)
    # Each array: a DELETEALL, then (when the report has contacts) the sphere list of the points.
    def contact_array(m):
        spheres = [k for k in m.markers if k.ns == "contacts"]
        return {"deleteall_first": bool(m.markers) and m.markers[0].action == 3,
                "type": spheres[0].type if spheres else None, "points": len(spheres[0].points) if spheres else 0}
    out["contact_markers"] = [contact_array(m) for m in msgs]

if req.get("service_states"):
    sv = [js(s) for s in req["service_states"]]
    if req.get("service_mapping") == "enhanced":
        r = call(dp, f"{ns.strip('/') + '/' if ns else ''}check_states", _types.RequestEnhanced, _types.ResponseEnhanced, _types.RequestEnhanced(states=sv))
    else:
        r = call(dp, f"{ns.strip('/') + '/' if ns else ''}check_states", Request, Response, None,
                 make=lambda k: Request(guid=0x1234567890ABCDEF, seq=k + 1, states=sv))
    if r is not None:
        out["service"] = [report_json(x) for x in r.reports]
        out["service_seq"] = int(getattr(r, "seq", 0))
if req.get("clock") is not None:
    cw = DataWriter(dp, Topic(dp, "rt/clock", _types.Clock), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(1)))
    ns_clock = int(req["clock"])
    for _ in range(30):
        cw.write(_types.Clock(clock=Time(sec=ns_clock // 1_000_000_000, nanosec=ns_clock % 1_000_000_000)))
        time.sleep(0.05)

if req.get("markers"):
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
    cells_r = DataReader(dp, Topic(dp, f"rt{ns}/collision_markers/cells", _types.MarkerArray), qos=latched)
    diag_r = DataReader(dp, Topic(dp, "rt/diagnostics", _types.DiagnosticArray), qos=reliable)
    end = time.time() + 10
    if req.get("clock") is not None:
        time.sleep(1.5)  # a status stamped after the clock arrived
        diag_r.take(N=100)
    cells, diag = None, None
    while time.time() < end and (cells is None or diag is None):
        for m in cells_r.take(N=10):
            cells = [{"ns": mk.ns, "type": mk.type, "points": len(mk.points), "frame": mk.header.frame_id} for mk in m.markers]
        for d in diag_r.take(N=10):
            diag = [{"name": st.name, "stamp": d.header.stamp.sec * 1_000_000_000 + d.header.stamp.nanosec, "values": {kv.key: kv.value for kv in st.values}} for st in d.status]
        time.sleep(0.02)
    out["cells_markers"] = cells
    out["diagnostics"] = diag

if req.get("tf_states"):
    tf_w = DataWriter(dp, Topic(dp, "rt/tf", TFMessage), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10)))
    end = time.time() + 15
    while tf_w.get_matched_subscriptions() == [] and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.3)
    out["tf_matched"] = tf_w.get_matched_subscriptions() != []
    out["tf_reports"] = []
    # First a message about somebody else's frame: warned about, no report.
    other = Time(sec=1, nanosec=0)
    tf_w.write(TFMessage(transforms=[TransformStamped(header=Header(stamp=other, frame_id="world"), child_frame_id="camera_link",
                                                      transform=Transform(translation=Vector3(x=0.0, y=0.0, z=1.0), rotation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)))]))
    time.sleep(0.3)
    out["tf_unknown_reports"] = len(collect(10, 0.5))
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
