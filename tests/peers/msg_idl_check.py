"""Self-check of msg_idl.py: the types it parses from the vendored moveit_msgs definitions
(tests/fixtures/msg_definitions/) are wire-identical to this project's hand-written ones.

- The values scene_cdr.py builds (with moveit_types.py's classes) go through msg_idl.to_json and
  msg_idl.from_json into msg_idl's classes, whose Cyclone serialisation (XCDR1 little endian,
  encapsulation header first, as the fixture files hold it) must equal
  tests/fixtures/planning_scene/collision_object.cdr and planning_scene.cdr byte for byte.
- The fixtures decode with msg_idl's classes and encode back to the same bytes.
- Every type of moveit_types.py that the vendored files define has the same fields in the same
  order with the same annotations, and the same DDS type name.
- The services: ApplyPlanningScene / GetPlanningScene with Cyclone's (guid, seq) header first.

Run with the peers' venv: python tests/peers/msg_idl_check.py; prints "ok" (raises otherwise).
"""
import contextlib
import io
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import msg_idl  # noqa: E402
import moveit_types  # noqa: E402

# scene_cdr.py is a peer: it reads {} from stdin and prints its hex when imported. Feed it and
# discard that; what is kept is its value-building functions.
with contextlib.redirect_stdout(io.StringIO()):
    stdin, sys.stdin = sys.stdin, io.StringIO("{}")
    try:
        import scene_cdr  # noqa: E402
    finally:
        sys.stdin = stdin

FIXTURES = HERE.parent / "fixtures" / "planning_scene"

# 1. The fixture bytes, from scene_cdr's values rebuilt with msg_idl's types.
for fixture, ros_type, value in [("collision_object", "moveit_msgs/msg/CollisionObject", scene_cdr.collision_object("sheet", 2)),
                                 ("planning_scene", "moveit_msgs/msg/PlanningScene", scene_cdr.planning_scene())]:
    kept = (FIXTURES / f"{fixture}.cdr").read_bytes()
    assert kept[:4] == b"\x00\x01\x00\x00", f"{fixture}.cdr: no CDR_LE encapsulation header"
    assert value.serialize() == kept, f"{fixture}: scene_cdr's own bytes differ from the fixture"
    as_json = msg_idl.to_json(value)
    msg = msg_idl.from_json(ros_type, as_json)
    assert type(msg) is msg_idl.idl(ros_type) and type(msg) is not type(value)
    assert msg.serialize() == kept, f"{fixture}: msg_idl's bytes differ from the fixture"
    assert msg_idl.to_json(msg) == as_json, f"{fixture}: to_json(from_json(x)) != x"
    # 2. Decoded by msg_idl's class and encoded back.
    back = msg_idl.idl(ros_type).deserialize(kept)
    assert back.serialize() == kept, f"{fixture}: decode/encode changed the bytes"
    assert msg_idl.from_json(ros_type, msg_idl.to_json(back)).serialize() == kept, f"{fixture}: JSON round trip changed the bytes"

# 3. Field by field against moveit_types.py's lists.
compared = 0
for key, cls in moveit_types.TYPES.items():
    pkg, name = key.split("/")
    if not (msg_idl.DEFS / pkg / "msg" / f"{name}.msg").exists():
        continue  # GetStateValidity's closure, diagnostic_msgs: not vendored
    ours = msg_idl.idl(f"{pkg}/msg/{name}")
    assert ours.__idl_typename__ == cls.__idl_typename__, key
    a, b = ours.__annotations__, cls.__annotations__
    assert list(a) == list(b), f"{key}: fields {list(a)} != {list(b)}"
    for f in a:
        assert repr(a[f]) == repr(b[f]), f"{key}.{f}: {a[f]!r} != {b[f]!r}"
    compared += 1
assert compared >= 30, compared

# 4. The services, with and without Cyclone's header.
apply_req, apply_resp = msg_idl.cyclone_service("moveit_msgs/srv/ApplyPlanningScene")
get_req, get_resp = msg_idl.cyclone_service("moveit_msgs/srv/GetPlanningScene")
assert list(apply_req.__annotations__) == ["guid", "seq", "scene"] and list(apply_resp.__annotations__) == ["guid", "seq", "success"]
assert list(get_req.__annotations__) == ["guid", "seq", "components"] and list(get_resp.__annotations__) == ["guid", "seq", "scene"]
assert apply_req.__idl_typename__ == "moveit_msgs::srv::dds_::ApplyPlanningScene_Request_"
assert get_resp.__idl_typename__ == "moveit_msgs::srv::dds_::GetPlanningScene_Response_"
plain_req, _ = msg_idl.service("moveit_msgs/srv/ApplyPlanningScene")
assert list(plain_req.__annotations__) == ["scene"]
r = get_req(guid=1, seq=2, components=msg_idl.from_json("moveit_msgs/msg/PlanningSceneComponents", {"components": 12}))
assert get_req.deserialize(r.serialize()) == r

# 5. from_json's defaults: zeros, empty sequences, fixed arrays of N, the .msg's own defaults.
empty = msg_idl.to_json(msg_idl.from_json("moveit_msgs/msg/CollisionObject", {}))
assert empty["pose"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}  # Quaternion.msg: float64 w 1
assert empty["primitives"] == [] and empty["operation"] == 0 and empty["header"]["frame_id"] == ""
assert msg_idl.to_json(msg_idl.from_json("shape_msgs/MeshTriangle", {})) == {"vertex_indices": [0, 0, 0]}
for bad in [{"nope": 1}, {"primitives": [{"dimensions": [1.0, 2.0, 3.0, 4.0]}]}]:
    try:
        msg_idl.from_json("moveit_msgs/msg/CollisionObject", bad)
    except ValueError:
        continue
    raise AssertionError(f"accepted {bad}")
print("ok")
