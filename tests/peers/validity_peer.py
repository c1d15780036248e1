"""The check_state_validity service (moveit_msgs/srv/GetStateValidity) called from an independent
ROS 2 participant (Cyclone DDS from Python), for tests/ros_validity.rs. Types from
tests/peers/moveit_types.py (this project's field lists), Cyclone's request/reply mapping, the
service name as move_group's tools use it (check_state_validity, under the node's namespace).
Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).

stdin: {"domain": id, "requests": [R...], "timeout": s}
        R = {"name": [...], "position": [... or "NaN"], "group": str (optional), "attached": bool or a box (see attached_object),
             "constraints": bool, "multi_dof": [names] (optional), "is_diff": bool, "pause": s to wait before sending}
stdout: {"answers": [A or null...], "refused_count": last /diagnostics check_state_validity_refused or null}
        A = {"valid", "contacts": [{"body_1", "type_1", "body_2", "type_2", "depth", "position", "normal", "frame"}],
             "cost_sources": n, "constraint_result": n}
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
import moveit_types as m  # noqa: E402
import service_client  # noqa: E402

req = json.load(sys.stdin)
dp = DomainParticipant(req["domain"])
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
timeout = req.get("timeout", 60)
GUID = 0x0123456789ABCDEF


def header(frame=""):
    return m.Header(stamp=m.Time(sec=0, nanosec=0), frame_id=frame)


def pose():
    return m.Pose(position=m.Point(x=0.0, y=0.0, z=0.0), orientation=m.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))


def attached_object(link, spec=None):
    """A box attached to `link`: 10 cm in the world frame at the origin, or as `spec` says
    ({"link", "id", "size": [x, y, z], "z": offset along the link's z, "touch_links": [...]}, given in the link's frame)."""
    spec = spec or {}
    link = spec.get("link", link)
    frame = link if spec else "world"
    offset = m.Pose(position=m.Point(x=0.0, y=0.0, z=float(spec.get("z", 0.0))), orientation=m.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))
    box = m.SolidPrimitive(type=1, dimensions=[float(x) for x in spec.get("size", [0.1, 0.1, 0.1])], polygon=m.Polygon(points=[]))
    obj = m.CollisionObject(header=header(frame), pose=pose(), id=spec.get("id", "held_box"), type=m.ObjectType(key="", db=""), primitives=[box],
                            primitive_poses=[offset], meshes=[], mesh_poses=[], planes=[], plane_poses=[], subframe_names=[],
                            subframe_poses=[], operation=0)
    posture = m.JointTrajectory(header=header(), joint_names=[], points=[])
    return m.AttachedCollisionObject(link_name=link, object=obj, touch_links=spec.get("touch_links", [link]), detach_posture=posture, weight=0.0)


def request(r, seq):
    js = m.JointState(header=header(), name=r.get("name", []), position=[float(x) for x in r.get("position", [])], velocity=[], effort=[])
    multi = r.get("multi_dof", [])
    identity = m.Transform(translation=m.Vector3(x=0.0, y=0.0, z=0.0), rotation=m.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))
    mdof = m.MultiDOFJointState(header=header(), joint_names=multi, transforms=[identity for _ in multi], twist=[], wrench=[])
    spec = r.get("attached")
    attached = [attached_object(r["name"][0] if r.get("name") else "tool0", spec if isinstance(spec, dict) else None)] if spec else []
    state = m.RobotState(joint_state=js, multi_dof_joint_state=mdof, attached_collision_objects=attached, is_diff=bool(r.get("is_diff")))
    joint_constraints = [m.JointConstraint(joint_name=r["name"][0], position=0.0, tolerance_above=0.1, tolerance_below=0.1, weight=1.0)] \
        if r.get("constraints") else []
    constraints = m.Constraints(name="", joint_constraints=joint_constraints, position_constraints=[], orientation_constraints=[],
                                visibility_constraints=[])
    return m.Request(guid=GUID, seq=seq, robot_state=state, group_name=r.get("group", ""), constraints=constraints)


def answer_json(a):
    return {"valid": bool(a.valid), "cost_sources": len(a.cost_sources), "constraint_result": len(a.constraint_result),
            "contacts": [{"body_1": c.contact_body_1, "type_1": int(c.body_type_1), "body_2": c.contact_body_2, "type_2": int(c.body_type_2),
                          "depth": c.depth, "position": [c.position.x, c.position.y, c.position.z],
                          "normal": [c.normal.x, c.normal.y, c.normal.z], "frame": c.header.frame_id} for c in a.contacts]}


req_w = DataWriter(dp, Topic(dp, "rq/check_state_validityRequest", m.Request), qos=reliable)
resp_r = DataReader(dp, Topic(dp, "rr/check_state_validityReply", m.Response), qos=reliable)
diag_r = DataReader(dp, Topic(dp, "rt/diagnostics", m.DiagnosticArray), qos=reliable)
end = time.time() + timeout
while (req_w.get_matched_subscriptions() == [] or resp_r.get_matched_publications() == []) and time.time() < end:
    time.sleep(0.05)
client = service_client.Client(req_w, resp_r, request)
send, wait_answer = client.send, client.wait_answer


# Warm-up: a request written before the node matched us is lost, so an empty request (the node's
# current state) is sent until one is answered; after that every request is written once.
while time.time() < end:
    if wait_answer(send({}), 1.0) is not None:
        break

out = {"answers": [], "refused_count": None}
for r in req["requests"]:
    time.sleep(r.get("pause", 0))
    a = wait_answer(send(r), max(1.0, end - time.time()))
    out["answers"].append(None if a is None else answer_json(a))

# The node's /diagnostics once a second: the count of requests not honoured.
want = req.get("refused_at_least", 0)
stop = min(end, time.time() + 5.0)
while time.time() < stop:
    for s in diag_r.take(N=100):
        for status in s.status:
            for kv in status.values:
                if kv.key == "check_state_validity_refused":
                    out["refused_count"] = int(kv.value)
    if out["refused_count"] is not None and out["refused_count"] >= want:
        break
    time.sleep(0.05)
json.dump(out, sys.stdout)
