"""The MoveIt application's side of the planning scene, as an independent ROS 2 participant (Cyclone
DDS from Python): it publishes moveit_msgs scene messages, calls the apply_planning_scene and
get_planning_scene services and sends joint states to the running node, reading its collision
reports back; or it writes the same messages into a rosbag2 bag with rosbags, for `replay`.
The moveit_msgs types (and shape_msgs, object_recognition_msgs, octomap_msgs...) are built from
moveit_msgs' own definition files, vendored in tests/fixtures/msg_definitions/, by msg_idl.py; a
message is given as JSON keyed by its .msg field names (msg_idl.from_json: a missing field takes
the .msg default or zero, floats also accept "NaN"/"inf"/"-inf").

stdin (live): {"op": "live", "domain": id, "ns": "" or "/ns", "timeout": s, "steps": [STEP...]}
  The peer waits up to `timeout` (default 30 s) for the endpoints the steps use to match: the
  writers of the topics published to, the joint_states writer (for "states"), the request writer
  and reply reader of each service called ("apply"; "get" and "wait_objects"). Then, in order:
  STEP                                               result (results[i] for steps[i])
  {"publish": "collision_object" | "attached_collision_object" | "planning_scene" |
   "planning_scene_world", "msg": {...}}             {} (written on rt{ns}/<publish>, reliable, volatile, KeepLast(10))
  {"apply": {...PlanningScene...}}                   {"success": bool}, or null without a reply in 10 s
  {"get": components}                                the reply's scene (msg_idl.to_json), or null after 10 s
  {"wait_objects": [ids], "attached": [ids]}         {"ok": bool, "seen": [world object ids, sorted]}: get_planning_scene
                                                     (WORLD_OBJECT_NAMES | ROBOT_STATE_ATTACHED_OBJECTS) every 50 ms until
                                                     the sorted world ids equal the list (and the sorted attached ids equal
                                                     "attached", if given), up to 10 s. With "attached" the result also
                                                     holds "seen_attached": [ids]
  {"states": [{"name": [...], "position": [...]}]}   [REPORT or null per state]: each state is published on rt{ns}/joint_states
                                                     (best effort) with a stamp from a run-wide counter (1 s, then +1 ms per
                                                     state) and its report (same header stamp) awaited up to 2 s; without a
                                                     report after 1 s the state is sent once more with the same stamp.
                                                     REPORT = {"stamp": ns, "in_collision", "error", "contacts": [{"link_name",
                                                     "object_name", "object_type", "triangle", "depth", "normal": [x, y, z],
                                                     "position": [x, y, z]}]}
  {"apply_streaming": {...PlanningScene...}, "state": {"name", "position"}, "period": s, "timeout": s}
                                                     {"success", "reply": s, "sent": n, "reports": [{"sent": s, "reported": s,
                                                     "objects": [...]}]}: apply_planning_scene called while the state is sent
                                                     every `period` (fresh stamps) until the reply; times from the request
  {"markers": {"present": [ns...], "absent": [ns...]}, "timeout": s}
                                                     {"ok": bool, "namespaces": [sorted ns of the newest array], "arrays": n}: the
                                                     latched rt{ns}/collision_markers/cells (reliable, transient local, keep last 1)
                                                     read until its newest MarkerArray has every "present" namespace and no "absent"
                                                     one, up to `timeout` (default 10 s)
  {"sleep": s}                                       {}
stdout (live): {"results": [...], "diagnostics": {key: value}} (the last value of each /diagnostics key, read until
  1.5 s after the last step).

stdin (bag): {"op": "bag", "path": dir, "storage": "mcap" | "sqlite3", "messages": [M...]}
  M = {"topic": "/collision_object" | "/attached_collision_object" | "/planning_scene" | "/planning_scene_world", "t": ns,
       "msg": {...}} (the moveit_msgs type of the topic);
      {"topic": "/joint_states", "t": ns, "name": [...], "position": [...], "stamp": ns (default: t)}
       (the three keys may also sit in "msg"; a "msg" with a "header" is a whole sensor_msgs/JointState);
      {"topic": "/robot_description", "t": ns, "data": urdf} (std_msgs/String).
  The types rosbags' ROS2_JAZZY store lacks are registered from the vendored .msg files.
stdout (bag): {"ok": true}.

Loopback only: the caller sets CYCLONEDDS_URI (127.0.0.1, no multicast, peer 127.0.0.1).
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import msg_idl  # noqa: E402

# The scene topics (stdin names without the slash) and their types.
SCENE_TOPICS = {"collision_object": "moveit_msgs/msg/CollisionObject", "attached_collision_object": "moveit_msgs/msg/AttachedCollisionObject",
                "planning_scene": "moveit_msgs/msg/PlanningScene", "planning_scene_world": "moveit_msgs/msg/PlanningSceneWorld"}
WORLD_OBJECT_NAMES, ROBOT_STATE_ATTACHED_OBJECTS = 8, 4  # moveit_msgs/msg/PlanningSceneComponents
SERVICE_WAIT = 10.0
GUID = 0x5C3E7E0A11CE0001


def joint_state_json(name, position, stamp_ns):
    """A sensor_msgs/JointState as msg_idl JSON."""
    return {"header": {"stamp": {"sec": stamp_ns // 1_000_000_000, "nanosec": stamp_ns % 1_000_000_000}, "frame_id": ""},
            "name": name, "position": position}


def live(req):
    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration
    import dds_types
    import service_client

    steps = req.get("steps", [])
    ns = req.get("ns", "")
    dp = DomainParticipant(req["domain"])
    # MoveIt's ServicesQoS for the scene topics; sensor data for joint states.
    scene_qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile, Policy.History.KeepLast(10))
    sensor = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10))
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))

    writers = {k: DataWriter(dp, Topic(dp, f"rt{ns}/{k}", msg_idl.idl(ty)), qos=scene_qos) for k, ty in SCENE_TOPICS.items()}
    JointState = msg_idl.idl("sensor_msgs/msg/JointState")
    js_w = DataWriter(dp, Topic(dp, f"rt{ns}/joint_states", JointState), qos=sensor)
    reports_r = DataReader(dp, Topic(dp, f"rt{ns}/collisions", dds_types.CollisionReport), qos=reliable)
    diag_r = DataReader(dp, Topic(dp, "rt/diagnostics", dds_types.DiagnosticArray), qos=reliable)
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
    cells_r = DataReader(dp, Topic(dp, f"rt{ns}/collision_markers/cells", dds_types.MarkerArray), qos=latched)

    def client(service, make):
        """A Cyclone-mapping service client (request writer, reply reader) for `service`."""
        Req, Resp = msg_idl.cyclone_service(f"moveit_msgs/srv/{service}")
        name = {"ApplyPlanningScene": "apply_planning_scene", "GetPlanningScene": "get_planning_scene"}[service]
        w = DataWriter(dp, Topic(dp, f"rq{ns}/{name}Request", Req), qos=reliable)
        r = DataReader(dp, Topic(dp, f"rr{ns}/{name}Reply", Resp), qos=reliable)
        return service_client.Client(w, r, lambda x, seq: make(Req, x, seq))

    apply_c = client("ApplyPlanningScene", lambda Req, scene, seq: Req(
        guid=GUID, seq=seq, scene=msg_idl.from_json("moveit_msgs/msg/PlanningScene", scene)))
    get_c = client("GetPlanningScene", lambda Req, c, seq: Req(
        guid=GUID, seq=seq, components=msg_idl.from_json("moveit_msgs/msg/PlanningSceneComponents", {"components": int(c)})))

    # Every message built before the first step: a bad step fails here, before anything is sent.
    for s in steps:
        if "publish" in s:
            msg_idl.from_json(SCENE_TOPICS[s["publish"]], s.get("msg", {}))
        elif "apply" in s:
            msg_idl.from_json("moveit_msgs/msg/PlanningScene", s["apply"])
        elif "apply_streaming" in s:
            msg_idl.from_json("moveit_msgs/msg/PlanningScene", s["apply_streaming"])

    # Wait for what the steps use to match.
    need_w = {writers[s["publish"]] for s in steps if "publish" in s}
    need_w |= {js_w} if any("states" in s or "apply_streaming" in s for s in steps) else set()
    need_c = [c for c, used in [(apply_c, any("apply" in s or "apply_streaming" in s for s in steps)),
                                (get_c, any("get" in s or "wait_objects" in s for s in steps))] if used]
    deadline = time.time() + req.get("timeout", 30)
    while time.time() < deadline and (any(w.get_matched_subscriptions() == [] for w in need_w) or any(
            c.request_writer.get_matched_subscriptions() == [] or c.reply_reader.get_matched_publications() == [] for c in need_c)):
        time.sleep(0.05)

    def call(c, x, wait=SERVICE_WAIT):
        return c.wait_answer(c.send(x), wait)

    def report_json(r):
        return {"stamp": r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec, "in_collision": bool(r.in_collision), "error": r.error,
                "contacts": [{"link_name": c.link_name, "object_name": c.object_name, "object_type": int(c.object_type), "triangle": int(c.triangle),
                              "depth": c.depth, "normal": [c.normal.x, c.normal.y, c.normal.z],
                              "position": [c.position.x, c.position.y, c.position.z]} for c in r.contacts]}

    next_stamp = [1_000_000_000]

    def state(s):
        """One joint state sent, and its report (or None)."""
        stamp = next_stamp[0]
        next_stamp[0] += 1_000_000
        msg = msg_idl.from_json("sensor_msgs/msg/JointState", joint_state_json(s.get("name", []), s.get("position", []), stamp))
        js_w.write(msg)
        start, resent = time.time(), False
        while time.time() < start + 2.0:
            for r in reports_r.take(N=100):
                # (a writer's dispose arrives as an InvalidSample, without fields)
                if hasattr(r, "header") and r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec == stamp:
                    return report_json(r)
            if not resent and time.time() >= start + 1.0:
                js_w.write(msg)  # the node may not have matched us when it was first sent
                resent = True
            time.sleep(0.005)
        return None

    def ids(scene):
        return sorted(o.id for o in scene.world.collision_objects), sorted(a.object.id for a in scene.robot_state.attached_collision_objects)

    def wait_objects(s):
        want, want_attached = sorted(s["wait_objects"]), (sorted(s["attached"]) if s.get("attached") is not None else None)
        end = time.time() + SERVICE_WAIT
        seen, seen_attached = [], []
        while True:
            a = call(get_c, WORLD_OBJECT_NAMES | ROBOT_STATE_ATTACHED_OBJECTS, min(1.0, max(0.05, end - time.time())))
            if a is not None:
                seen, seen_attached = ids(a.scene)
                if seen == want and (want_attached is None or seen_attached == want_attached):
                    ok = True
                    break
            if time.time() >= end:
                ok = False
                break
            time.sleep(0.05)
        out = {"ok": ok, "seen": seen}
        if want_attached is not None:
            out["seen_attached"] = seen_attached
        return out

    def apply_streaming(s):
        """apply_planning_scene called while joint states stream: the reply's time, and each
        state's send and report times (seconds from the request) and the objects it touched."""
        scene = s["apply_streaming"]
        k = apply_c.send(scene)
        t0, period, sent, reports, reply_at, success = time.time(), float(s.get("period", 0.005)), {}, {}, None, None
        end = t0 + float(s.get("timeout", 20.0))
        next_send = t0
        while time.time() < end and (reply_at is None or time.time() < reply_at + 0.3):
            now = time.time()
            if reply_at is None and now >= next_send:
                stamp = next_stamp[0]
                next_stamp[0] += 1_000_000
                js_w.write(msg_idl.from_json("sensor_msgs/msg/JointState", joint_state_json(s["state"]["name"], s["state"]["position"], stamp)))
                sent[stamp] = now - t0
                next_send = now + period
            for r in reports_r.take(N=100):
                if hasattr(r, "header"):
                    st = r.header.stamp.sec * 1_000_000_000 + r.header.stamp.nanosec
                    if st in sent and st not in reports:
                        reports[st] = {"sent": sent[st], "reported": time.time() - t0, "objects": sorted({c.object_name for c in r.contacts})}
            for x in apply_c.reply_reader.take(N=10):
                if int(x.seq) == k and reply_at is None:
                    reply_at, success = time.time(), bool(x.success)
            time.sleep(0.001)
        return {"success": success, "reply": None if reply_at is None else reply_at - t0, "sent": len(sent),
                "reports": [reports[st] for st in sorted(reports)]}

    newest_cells = [None, 0]

    def markers(s):
        want, avoid = set(s["markers"].get("present", [])), set(s["markers"].get("absent", []))
        end = time.time() + float(s.get("timeout", 10.0))
        while True:
            for m in cells_r.take(N=10):
                if hasattr(m, "markers"):
                    newest_cells[0] = sorted({mk.ns for mk in m.markers if mk.ns})
                    newest_cells[1] += 1
            seen = set(newest_cells[0] or [])
            ok = newest_cells[0] is not None and want <= seen and not (avoid & seen)
            if ok or time.time() >= end:
                return {"ok": ok, "namespaces": newest_cells[0], "arrays": newest_cells[1]}
            time.sleep(0.02)

    results = []
    for s in steps:
        if "publish" in s:
            writers[s["publish"]].write(msg_idl.from_json(SCENE_TOPICS[s["publish"]], s.get("msg", {})))
            results.append({})
        elif "apply" in s:
            a = call(apply_c, s["apply"])
            results.append(None if a is None else {"success": bool(a.success)})
        elif "get" in s:
            a = call(get_c, s["get"])
            results.append(None if a is None else msg_idl.to_json(a.scene))
        elif "wait_objects" in s:
            results.append(wait_objects(s))
        elif "states" in s:
            results.append([state(x) for x in s["states"]])
        elif "apply_streaming" in s:
            results.append(apply_streaming(s))
        elif "markers" in s:
            results.append(markers(s))
        elif "sleep" in s:
            time.sleep(float(s["sleep"]))
            results.append({})
        else:
            raise ValueError(f"unknown step {s}")

    # A status after the last step (the node publishes /diagnostics once a second); the reader
    # keeps the whole run's samples, so the last value of each key wins.
    diagnostics = {}
    end = time.time() + 1.5
    while True:
        for d in diag_r.take(N=100):
            for st in getattr(d, "status", []):
                diagnostics.update({kv.key: kv.value for kv in st.values})
        if time.time() >= end:
            break
        time.sleep(0.05)
    return {"results": results, "diagnostics": diagnostics}


def bag(req):
    import numpy as np
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore, get_types_from_msg
    store = get_typestore(Stores.ROS2_JAZZY)
    # Register, from the vendored definitions, every message type the store lacks (moveit_msgs,
    # object_recognition_msgs, octomap_msgs); the ones it has (shape_msgs...) are left as they are.
    lacking = {}
    for f in sorted(msg_idl.DEFS.glob("*/msg/*.msg")):
        name = f"{f.parent.parent.name}/msg/{f.stem}"
        if name not in store.types:
            lacking.update(get_types_from_msg(f.read_text(), name))
    store.register(lacking)
    S = store.types
    dtypes = {"bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8, "uint8": np.uint8, "int16": np.int16, "uint16": np.uint16,
              "int32": np.int32, "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64, "float32": np.float32, "float64": np.float64}

    def build(ty, value):
        """A rosbags message from JSON, along msg_idl's reading of the vendored definition."""
        return msg_idl.from_json(ty, value, make=lambda name, kw: S[name](**kw),
                                 prim_seq=lambda base, xs: xs if base == "string" else np.array(xs, dtype=dtypes[base]))

    topic_types = {f"/{k}": ty for k, ty in SCENE_TOPICS.items()}
    topic_types.update({"/joint_states": "sensor_msgs/msg/JointState", "/robot_description": "std_msgs/msg/String"})
    plugin = StoragePlugin.MCAP if req["storage"] == "mcap" else StoragePlugin.SQLITE3
    with Writer(req["path"], version=8, storage_plugin=plugin) as w:
        conns = {}
        for m in req["messages"]:
            topic = m["topic"]
            ty = topic_types[topic]
            if topic not in conns:
                conns[topic] = w.add_connection(topic, ty, typestore=store)
            if topic == "/robot_description":
                msg = S[ty](data=m["data"])
            elif topic == "/joint_states":
                src = m.get("msg", m)
                value = src if "header" in src else joint_state_json(src.get("name", []), src.get("position", []), int(src.get("stamp", m["t"])))
                msg = build(ty, value)
            else:
                msg = build(ty, m.get("msg", {}))
            w.write(conns[topic], int(m["t"]), store.serialize_cdr(msg, ty))
    return {"ok": True}


if __name__ == "__main__":
    req = json.load(sys.stdin)
    json.dump({"live": live, "bag": bag}[req["op"]](req), sys.stdout)
