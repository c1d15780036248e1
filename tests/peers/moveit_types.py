"""Cyclone DDS IDL types for moveit_msgs/srv/GetStateValidity and moveit_msgs/msg/PlanningScene and
everything they carry, built from this project's own field lists (below), for
tests/peers/validity_peer.py and tests/peers/scene_cdr.py. The lists were checked field by field
against the moveit_msgs ros2 branch (msg/*.msg, srv/GetStateValidity.srv) and common_interfaces
(jazzy: shape_msgs, sensor_msgs, geometry_msgs, trajectory_msgs, std_msgs), plus
object_recognition_msgs and octomap_msgs (ros2 branches), diagnostic_msgs and builtin_interfaces;
constants are left out (they do not travel). Field order is wire order; the Rust side is
src/msgs/moveit.rs and src/msgs/planning_scene.rs.

A field is "TYPE NAME"; TYPE is a primitive, a full "pkg/Type" name, or either followed by "[]"
(sequence), "[<=N]" (bounded sequence) or "[N]" (fixed array)."""
import re
import types
from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t


def struct_typed(ros_type, fields):
    """An IDL struct named as ROS 2 names DDS types: pkg::msg::dds_::Type_ (as dds_types.py does;
    this file stands alone so the peer depends on nothing else)."""
    pkg, kind, name = ros_type.split("/")
    cls = types.new_class(name, (IdlStruct,), {"typename": f"{pkg}::{kind}::dds_::{name}_"},
                          lambda ns: ns.update({"__annotations__": dict(fields)}))
    return dataclass(cls)


FIELDS = [
    # builtin_interfaces, std_msgs, geometry_msgs, sensor_msgs, trajectory_msgs, diagnostic_msgs.
    ("builtin_interfaces/msg/Time", "int32 sec; uint32 nanosec"),
    ("builtin_interfaces/msg/Duration", "int32 sec; uint32 nanosec"),
    ("std_msgs/msg/Header", "builtin_interfaces/Time stamp; string frame_id"),
    ("geometry_msgs/msg/Point", "float64 x; float64 y; float64 z"),
    ("geometry_msgs/msg/Vector3", "float64 x; float64 y; float64 z"),
    ("geometry_msgs/msg/Quaternion", "float64 x; float64 y; float64 z; float64 w"),
    ("geometry_msgs/msg/Pose", "geometry_msgs/Point position; geometry_msgs/Quaternion orientation"),
    ("geometry_msgs/msg/Transform", "geometry_msgs/Vector3 translation; geometry_msgs/Quaternion rotation"),
    ("sensor_msgs/msg/JointState", "std_msgs/Header header; string[] name; float64[] position; float64[] velocity; float64[] effort"),
    ("trajectory_msgs/msg/JointTrajectoryPoint",
     "float64[] positions; float64[] velocities; float64[] accelerations; float64[] effort; builtin_interfaces/Duration time_from_start"),
    ("trajectory_msgs/msg/JointTrajectory", "std_msgs/Header header; string[] joint_names; trajectory_msgs/JointTrajectoryPoint[] points"),
    ("diagnostic_msgs/msg/KeyValue", "string key; string value"),
    ("diagnostic_msgs/msg/DiagnosticStatus", "byte level; string name; string message; string hardware_id; diagnostic_msgs/KeyValue[] values"),
    ("diagnostic_msgs/msg/DiagnosticArray", "std_msgs/Header header; diagnostic_msgs/DiagnosticStatus[] status"),
    # The closure of moveit_msgs/srv/GetStateValidity.
    ("geometry_msgs/msg/Point32", "float32 x; float32 y; float32 z"),
    ("geometry_msgs/msg/Polygon", "geometry_msgs/Point32[] points"),
    ("geometry_msgs/msg/Twist", "geometry_msgs/Vector3 linear; geometry_msgs/Vector3 angular"),
    ("geometry_msgs/msg/Wrench", "geometry_msgs/Vector3 force; geometry_msgs/Vector3 torque"),
    ("geometry_msgs/msg/PoseStamped", "std_msgs/Header header; geometry_msgs/Pose pose"),
    ("sensor_msgs/msg/MultiDOFJointState",
     "std_msgs/Header header; string[] joint_names; geometry_msgs/Transform[] transforms; geometry_msgs/Twist[] twist;"
     " geometry_msgs/Wrench[] wrench"),
    ("shape_msgs/msg/SolidPrimitive", "uint8 type; float64[<=3] dimensions; geometry_msgs/Polygon polygon"),
    ("shape_msgs/msg/MeshTriangle", "uint32[3] vertex_indices"),
    ("shape_msgs/msg/Mesh", "shape_msgs/MeshTriangle[] triangles; geometry_msgs/Point[] vertices"),
    ("shape_msgs/msg/Plane", "float64[4] coef"),
    ("object_recognition_msgs/msg/ObjectType", "string key; string db"),
    ("moveit_msgs/msg/CollisionObject",
     "std_msgs/Header header; geometry_msgs/Pose pose; string id; object_recognition_msgs/ObjectType type;"
     " shape_msgs/SolidPrimitive[] primitives; geometry_msgs/Pose[] primitive_poses; shape_msgs/Mesh[] meshes;"
     " geometry_msgs/Pose[] mesh_poses; shape_msgs/Plane[] planes; geometry_msgs/Pose[] plane_poses; string[] subframe_names;"
     " geometry_msgs/Pose[] subframe_poses; byte operation"),
    ("moveit_msgs/msg/AttachedCollisionObject",
     "string link_name; moveit_msgs/CollisionObject object; string[] touch_links; trajectory_msgs/JointTrajectory detach_posture;"
     " float64 weight"),
    ("moveit_msgs/msg/RobotState",
     "sensor_msgs/JointState joint_state; sensor_msgs/MultiDOFJointState multi_dof_joint_state;"
     " moveit_msgs/AttachedCollisionObject[] attached_collision_objects; bool is_diff"),
    ("moveit_msgs/msg/JointConstraint", "string joint_name; float64 position; float64 tolerance_above; float64 tolerance_below; float64 weight"),
    ("moveit_msgs/msg/BoundingVolume",
     "shape_msgs/SolidPrimitive[] primitives; geometry_msgs/Pose[] primitive_poses; shape_msgs/Mesh[] meshes; geometry_msgs/Pose[] mesh_poses"),
    ("moveit_msgs/msg/PositionConstraint",
     "std_msgs/Header header; string link_name; geometry_msgs/Vector3 target_point_offset; moveit_msgs/BoundingVolume constraint_region;"
     " float64 weight"),
    ("moveit_msgs/msg/OrientationConstraint",
     "std_msgs/Header header; geometry_msgs/Quaternion orientation; string link_name; float64 absolute_x_axis_tolerance;"
     " float64 absolute_y_axis_tolerance; float64 absolute_z_axis_tolerance; uint8 parameterization; float64 weight"),
    ("moveit_msgs/msg/VisibilityConstraint",
     "float64 target_radius; geometry_msgs/PoseStamped target_pose; int32 cone_sides; geometry_msgs/PoseStamped sensor_pose;"
     " float64 max_view_angle; float64 max_range_angle; uint8 sensor_view_direction; float64 weight"),
    ("moveit_msgs/msg/Constraints",
     "string name; moveit_msgs/JointConstraint[] joint_constraints; moveit_msgs/PositionConstraint[] position_constraints;"
     " moveit_msgs/OrientationConstraint[] orientation_constraints; moveit_msgs/VisibilityConstraint[] visibility_constraints"),
    ("moveit_msgs/msg/ContactInformation",
     "std_msgs/Header header; geometry_msgs/Point position; geometry_msgs/Vector3 normal; float64 depth; string contact_body_1;"
     " uint32 body_type_1; string contact_body_2; uint32 body_type_2"),
    ("moveit_msgs/msg/CostSource", "float64 cost_density; geometry_msgs/Vector3 aabb_min; geometry_msgs/Vector3 aabb_max"),
    ("moveit_msgs/msg/ConstraintEvalResult", "bool result; float64 distance"),
    # The rest of moveit_msgs/msg/PlanningScene.
    ("std_msgs/msg/ColorRGBA", "float32 r; float32 g; float32 b; float32 a"),
    ("geometry_msgs/msg/TransformStamped", "std_msgs/Header header; string child_frame_id; geometry_msgs/Transform transform"),
    ("octomap_msgs/msg/Octomap", "std_msgs/Header header; bool binary; string id; float64 resolution; int8[] data"),
    ("octomap_msgs/msg/OctomapWithPose", "std_msgs/Header header; geometry_msgs/Pose origin; octomap_msgs/Octomap octomap"),
    ("moveit_msgs/msg/PlanningSceneWorld", "moveit_msgs/CollisionObject[] collision_objects; octomap_msgs/OctomapWithPose octomap"),
    ("moveit_msgs/msg/AllowedCollisionEntry", "bool[] enabled"),
    ("moveit_msgs/msg/AllowedCollisionMatrix",
     "string[] entry_names; moveit_msgs/AllowedCollisionEntry[] entry_values; string[] default_entry_names; bool[] default_entry_values"),
    ("moveit_msgs/msg/LinkPadding", "string link_name; float64 padding"),
    ("moveit_msgs/msg/LinkScale", "string link_name; float64 scale"),
    ("moveit_msgs/msg/ObjectColor", "string id; std_msgs/ColorRGBA color"),
    ("moveit_msgs/msg/PlanningScene",
     "string name; moveit_msgs/RobotState robot_state; string robot_model_name; geometry_msgs/TransformStamped[] fixed_frame_transforms;"
     " moveit_msgs/AllowedCollisionMatrix allowed_collision_matrix; moveit_msgs/LinkPadding[] link_padding;"
     " moveit_msgs/LinkScale[] link_scale; moveit_msgs/ObjectColor[] object_colors; moveit_msgs/PlanningSceneWorld world; bool is_diff"),
    # moveit_msgs/srv/ApplyPlanningScene in the enhanced mapping (no request header): for the Fast DDS peer.
    ("moveit_msgs/srv/ApplyPlanningScene_Request", "moveit_msgs/PlanningScene scene"),
    ("moveit_msgs/srv/ApplyPlanningScene_Response", "bool success"),
    # Cyclone's request/reply mapping: a (guid, seq) header before the .srv's fields.
    ("moveit_msgs/srv/GetStateValidity_Request",
     "uint64 guid; int64 seq; moveit_msgs/RobotState robot_state; string group_name; moveit_msgs/Constraints constraints"),
    ("moveit_msgs/srv/GetStateValidity_Response",
     "uint64 guid; int64 seq; bool valid; moveit_msgs/ContactInformation[] contacts; moveit_msgs/CostSource[] cost_sources;"
     " moveit_msgs/ConstraintEvalResult[] constraint_result"),
]

PRIMS = {"bool": bool, "byte": t.byte, "int8": t.int8, "uint8": t.uint8, "int32": t.int32, "uint32": t.uint32, "int64": t.int64, "uint64": t.uint64,
         "float32": t.float32, "float64": t.float64, "string": str}
TYPES = {}


def _field_type(spec):
    m = re.fullmatch(r"([A-Za-z0-9_/]+)(?:\[(<=)?(\d*)\])?", spec)
    if m is None:
        raise ValueError(f"bad field type {spec}")
    base, bounded, n = m.groups()
    py = PRIMS.get(base) or TYPES.get(base)
    if py is None:
        raise ValueError(f"unknown type {base}")
    if "[" not in spec:
        return py
    if n == "":
        return t.sequence[py]
    return t.sequence[py, int(n)] if bounded else t.array[py, int(n)]


for ros_type, text in FIELDS:
    fields = []
    for f in text.split(";"):
        ty, name = f.split()
        fields.append((name, _field_type(ty)))
    pkg, _kind, name = ros_type.split("/")
    TYPES[f"{pkg}/{name}"] = struct_typed(ros_type, fields)

Time, Header, Point, Vector3, Quaternion, Pose, Transform = (TYPES[n] for n in (
    "builtin_interfaces/Time", "std_msgs/Header", "geometry_msgs/Point", "geometry_msgs/Vector3", "geometry_msgs/Quaternion",
    "geometry_msgs/Pose", "geometry_msgs/Transform"))
JointState = TYPES["sensor_msgs/JointState"]
JointTrajectory = TYPES["trajectory_msgs/JointTrajectory"]
DiagnosticArray = TYPES["diagnostic_msgs/DiagnosticArray"]
RobotState = TYPES["moveit_msgs/RobotState"]
MultiDOFJointState = TYPES["sensor_msgs/MultiDOFJointState"]
AttachedCollisionObject = TYPES["moveit_msgs/AttachedCollisionObject"]
CollisionObject = TYPES["moveit_msgs/CollisionObject"]
ObjectType = TYPES["object_recognition_msgs/ObjectType"]
SolidPrimitive = TYPES["shape_msgs/SolidPrimitive"]
Polygon = TYPES["geometry_msgs/Polygon"]
Constraints = TYPES["moveit_msgs/Constraints"]
JointConstraint = TYPES["moveit_msgs/JointConstraint"]
Request = TYPES["moveit_msgs/GetStateValidity_Request"]
Response = TYPES["moveit_msgs/GetStateValidity_Response"]
ApplyRequest = TYPES["moveit_msgs/ApplyPlanningScene_Request"]
ApplyResponse = TYPES["moveit_msgs/ApplyPlanningScene_Response"]

# The same service without Cyclone's header: the enhanced mapping (Fast DDS, rmw_fastrtps_cpp),
# for the Fast DDS peer (tests/peers/fastdds/ros_idl.py takes this form where both exist).
RequestEnhanced = struct_typed("moveit_msgs/srv/GetStateValidity_Request",
                               [(n, a) for n, a in Request.__annotations__.items() if n not in ("guid", "seq")])
ResponseEnhanced = struct_typed("moveit_msgs/srv/GetStateValidity_Response",
                                [(n, a) for n, a in Response.__annotations__.items() if n not in ("guid", "seq")])
