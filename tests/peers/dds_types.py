"""Cyclone DDS IDL types for the ROS 2 messages the node speaks, named as ROS 2 names them
(pkg::msg::dds_::Type_); the project's own types are built from its .msg files."""
import types
from dataclasses import dataclass
from pathlib import Path

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t

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
String = struct_typed("std_msgs/msg/String", [("data", str)])
Quaternion = struct_typed("geometry_msgs/msg/Quaternion", [("x", t.float64), ("y", t.float64), ("z", t.float64), ("w", t.float64)])
Transform = struct_typed("geometry_msgs/msg/Transform", [("translation", Vector3), ("rotation", Quaternion)])
TransformStamped = struct_typed("geometry_msgs/msg/TransformStamped", [("header", Header), ("child_frame_id", str), ("transform", Transform)])
TFMessage = struct_typed("tf2_msgs/msg/TFMessage", [("transforms", t.sequence[TransformStamped])])
KNOWN = {"std_msgs/Header": Header, "geometry_msgs/Point": Point, "geometry_msgs/Vector3": Vector3, "sensor_msgs/JointState": JointState}
PRIMS = {"string": str, "bool": bool, "uint8": t.uint8, "uint32": t.uint32, "int32": t.int32, "float64": t.float64}


def from_msg(pkg, kind, name, text, local):
    """A Cyclone IDL struct from a .msg definition (the project's own files)."""
    fields = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line or "=" in line:  # a blank line, or a constant (not on the wire)
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
local["Clearance"] = from_msg("thickness_collision_msgs", "msg", "Clearance", (IFACE / "msg/Clearance.msg").read_text(), local)
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
# list_parameters and describe_parameters, as `ros2 param list` / `ros2 param describe` call them
# (the Fast DDS peer, tests/peers/fastdds/peer.cpp, uses these through ros_idl.py).
ListReq = struct_typed("rcl_interfaces/srv/ListParameters_Request", [("prefixes", t.sequence[str]), ("depth", t.uint64)])
ListParametersResult = struct_typed("rcl_interfaces/msg/ListParametersResult", [("names", t.sequence[str]), ("prefixes", t.sequence[str])])
ListResp = struct_typed("rcl_interfaces/srv/ListParameters_Response", [("result", ListParametersResult)])
FloatingPointRange = struct_typed("rcl_interfaces/msg/FloatingPointRange", [("from_value", t.float64), ("to_value", t.float64), ("step", t.float64)])
IntegerRange = struct_typed("rcl_interfaces/msg/IntegerRange", [("from_value", t.int64), ("to_value", t.int64), ("step", t.uint64)])
ParameterDescriptor = struct_typed("rcl_interfaces/msg/ParameterDescriptor", [
    ("name", str), ("type", t.uint8), ("description", str), ("additional_constraints", str), ("read_only", bool), ("dynamic_typing", bool),
    ("floating_point_range", t.sequence[FloatingPointRange, 1]), ("integer_range", t.sequence[IntegerRange, 1])])
DescribeReq = struct_typed("rcl_interfaces/srv/DescribeParameters_Request", [("names", t.sequence[str])])
DescribeResp = struct_typed("rcl_interfaces/srv/DescribeParameters_Response", [("descriptors", t.sequence[ParameterDescriptor])])
GetTypesReq = struct_typed("rcl_interfaces/srv/GetParameterTypes_Request", [("names", t.sequence[str])])
GetTypesResp = struct_typed("rcl_interfaces/srv/GetParameterTypes_Response", [("types", t.sequence[t.uint8])])
SetAtomicReq = struct_typed("rcl_interfaces/srv/SetParametersAtomically_Request", [("parameters", t.sequence[Parameter])])
SetAtomicResp = struct_typed("rcl_interfaces/srv/SetParametersAtomically_Response", [("result", SetParametersResult)])

# visualization_msgs and diagnostic_msgs, to read the node's markers and status.
ColorRGBA = struct_typed("std_msgs/msg/ColorRGBA", [("r", t.float32), ("g", t.float32), ("b", t.float32), ("a", t.float32)])
PoseMsg = struct_typed("geometry_msgs/msg/Pose", [("position", Point), ("orientation", Quaternion)])
DurationMsg = struct_typed("builtin_interfaces/msg/Duration", [("sec", t.int32), ("nanosec", t.uint32)])
CompressedImage = struct_typed("sensor_msgs/msg/CompressedImage", [("header", Header), ("format", str), ("data", t.sequence[t.uint8])])
UVCoordinate = struct_typed("visualization_msgs/msg/UVCoordinate", [("u", t.float32), ("v", t.float32)])
MeshFile = struct_typed("visualization_msgs/msg/MeshFile", [("filename", str), ("data", t.sequence[t.uint8])])
Marker = struct_typed("visualization_msgs/msg/Marker", [
    ("header", Header), ("ns", str), ("id", t.int32), ("type", t.int32), ("action", t.int32), ("pose", PoseMsg), ("scale", Vector3),
    ("color", ColorRGBA), ("lifetime", DurationMsg), ("frame_locked", bool), ("points", t.sequence[Point]), ("colors", t.sequence[ColorRGBA]),
    ("texture_resource", str), ("texture", CompressedImage), ("uv_coordinates", t.sequence[UVCoordinate]), ("text", str),
    ("mesh_resource", str), ("mesh_file", MeshFile), ("mesh_use_embedded_materials", bool)])
MarkerArray = struct_typed("visualization_msgs/msg/MarkerArray", [("markers", t.sequence[Marker])])
KeyValue = struct_typed("diagnostic_msgs/msg/KeyValue", [("key", str), ("value", str)])
DiagnosticStatus = struct_typed("diagnostic_msgs/msg/DiagnosticStatus", [("level", t.uint8), ("name", str), ("message", str), ("hardware_id", str), ("values", t.sequence[KeyValue])])
DiagnosticArray = struct_typed("diagnostic_msgs/msg/DiagnosticArray", [("header", Header), ("status", t.sequence[DiagnosticStatus])])
Clock = struct_typed("rosgraph_msgs/msg/Clock", [("clock", Time)])
# check_states without the Cyclone header, for the "enhanced" mapping.
RequestEnhanced = struct_typed("thickness_collision_msgs/srv/CheckStates_Request", [("states", t.sequence[JointState])])
ResponseEnhanced = struct_typed("thickness_collision_msgs/srv/CheckStates_Response", [("reports", t.sequence[CollisionReport])])

# check_trajectory: trajectory_msgs, and the service's parts built from CheckTrajectory.srv.
JointTrajectoryPoint = struct_typed("trajectory_msgs/msg/JointTrajectoryPoint", [
    ("positions", t.sequence[t.float64]), ("velocities", t.sequence[t.float64]), ("accelerations", t.sequence[t.float64]),
    ("effort", t.sequence[t.float64]), ("time_from_start", DurationMsg)])
JointTrajectory = struct_typed("trajectory_msgs/msg/JointTrajectory", [("header", Header), ("joint_names", t.sequence[str]),
                                                                       ("points", t.sequence[JointTrajectoryPoint])])
KNOWN["builtin_interfaces/Duration"] = DurationMsg
KNOWN["trajectory_msgs/JointTrajectory"] = JointTrajectory
_traj_req, _traj_resp = (IFACE / "srv/CheckTrajectory.srv").read_text().split("---")
TrajReqBody = from_msg("thickness_collision_msgs", "srv", "CheckTrajectory_Request", _traj_req, local)
TrajRespBody = from_msg("thickness_collision_msgs", "srv", "CheckTrajectory_Response", _traj_resp, local)


def _with_header(ros_type, body):
    """The Cyclone request/reply mapping: a (guid, seq) header before the .srv's fields."""
    return struct_typed(ros_type, [("guid", t.uint64), ("seq", t.int64)] + list(body.__annotations__.items()))


TrajRequest = _with_header("thickness_collision_msgs/srv/CheckTrajectory_Request", TrajReqBody)
TrajResponse = _with_header("thickness_collision_msgs/srv/CheckTrajectory_Response", TrajRespBody)
