"""A populated moveit_msgs/msg/CollisionObject and PlanningScene as Cyclone DDS serialises them
(the bytes a Cyclone peer publishes: XCDR1 little endian, encapsulation header first), from the
IDL types of tests/peers/moveit_types.py, for tests/msgs_interface.rs. The values are those of
`collision_object` and `planning_scene` in src/msgs/planning_scene_tests.rs, which checks that
the crate encodes them to the bytes kept in tests/fixtures/planning_scene/ and decodes those
bytes back to them; this peer's bytes are compared with the same files.

stdin: {} (ignored)
stdout: {"collision_object": hex, "planning_scene": hex}
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import moveit_types as m  # noqa: E402

T = m.TYPES
json.load(sys.stdin)


def pose(x, y, z):
    return m.Pose(position=m.Point(x=x, y=y, z=z), orientation=m.Quaternion(x=0.0, y=0.0, z=0.38268343236508984, w=0.9238795325112867))


def identity_pose():
    return m.Pose(position=m.Point(x=0.0, y=0.0, z=0.0), orientation=m.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))


def header(frame, sec):
    return m.Header(stamp=m.Time(sec=sec, nanosec=250_000_000), frame_id=frame)


def vec(x, y, z):
    return m.Vector3(x=x, y=y, z=z)


def collision_object(oid, operation):
    square = [(-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1)]
    box = m.SolidPrimitive(type=1, dimensions=[0.2, 0.3, 0.4], polygon=m.Polygon(points=[]))
    prism = m.SolidPrimitive(type=5, dimensions=[0.05], polygon=m.Polygon(points=[T["geometry_msgs/Point32"](x=x, y=y, z=0.0) for x, y in square]))
    tri = T["shape_msgs/MeshTriangle"]
    mesh = T["shape_msgs/Mesh"](triangles=[tri(vertex_indices=[0, 1, 2]), tri(vertex_indices=[0, 2, 3])],
                                vertices=[m.Point(x=0.0, y=0.0, z=0.0), m.Point(x=1.0, y=0.0, z=0.0), m.Point(x=1.0, y=1.0, z=0.0),
                                          m.Point(x=0.0, y=1.0, z=0.0)])
    return m.CollisionObject(header=header("world", 7), pose=pose(0.5, -0.25, 0.125), id=oid,
                             type=m.ObjectType(key="fixture", db="{'type':'none'}"), primitives=[box, prism],
                             primitive_poses=[pose(0.0, 0.0, 0.2), pose(0.1, 0.0, 0.0)], meshes=[mesh], mesh_poses=[pose(0.0, 0.0, 1.0)],
                             planes=[T["shape_msgs/Plane"](coef=[0.0, 0.0, 1.0, -0.5])], plane_poses=[identity_pose()],
                             subframe_names=["tip", "base"], subframe_poses=[pose(0.0, 0.0, 0.3), identity_pose()], operation=operation)


def planning_scene():
    point = T["trajectory_msgs/JointTrajectoryPoint"](positions=[0.04], velocities=[0.0], accelerations=[], effort=[1.5],
                                                      time_from_start=T["builtin_interfaces/Duration"](sec=1, nanosec=5))
    tray = m.AttachedCollisionObject(link_name="tool0", object=collision_object("tray", 0), touch_links=["tool0", "wrist_3_link"],
                                     detach_posture=m.JointTrajectory(header=header("", 1), joint_names=["finger"], points=[point]),
                                     weight=0.75)
    moved = m.Transform(translation=vec(1.0, 2.0, 3.0), rotation=m.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))
    state = m.RobotState(
        joint_state=m.JointState(header=header("", 3), name=["shoulder", "elbow"], position=[0.5, -1.25], velocity=[], effort=[]),
        multi_dof_joint_state=m.MultiDOFJointState(
            header=header("world", 3), joint_names=["base"], transforms=[moved],
            twist=[T["geometry_msgs/Twist"](linear=vec(0.1, 0.0, 0.0), angular=vec(0.0, 0.0, 0.0))],
            wrench=[T["geometry_msgs/Wrench"](force=vec(0.0, 0.0, -9.81), torque=vec(0.0, 0.0, 0.0))]),
        attached_collision_objects=[tray], is_diff=True)
    entry = T["moveit_msgs/AllowedCollisionEntry"]
    acm = T["moveit_msgs/AllowedCollisionMatrix"](entry_names=["tool0", "sheet"], entry_values=[entry(enabled=[False, True]), entry(enabled=[True, False])],
                                                  default_entry_names=["wall"], default_entry_values=[True])
    # The tree's bytes 0, 1, 127, 128, 200, 255 as int8.
    octomap = T["octomap_msgs/Octomap"](header=header("world", 9), binary=True, id="OcTree", resolution=0.05, data=[0, 1, 127, -128, -56, -1])
    world = T["moveit_msgs/PlanningSceneWorld"](
        collision_objects=[collision_object("sheet", 0), collision_object("wall", 3)],
        octomap=T["octomap_msgs/OctomapWithPose"](header=header("world", 9), origin=pose(0.0, 0.0, 0.5), octomap=octomap))
    return T["moveit_msgs/PlanningScene"](
        name="cell", robot_state=state, robot_model_name="ur5e",
        fixed_frame_transforms=[T["geometry_msgs/TransformStamped"](header=header("world", 0), child_frame_id="table", transform=moved)],
        allowed_collision_matrix=acm, link_padding=[T["moveit_msgs/LinkPadding"](link_name="tool0", padding=0.01)],
        link_scale=[T["moveit_msgs/LinkScale"](link_name="wrist_3_link", scale=1.1)],
        object_colors=[T["moveit_msgs/ObjectColor"](id="sheet", color=T["std_msgs/ColorRGBA"](r=0.5, g=0.25, b=1.0, a=0.8))],
        world=world, is_diff=False)


json.dump({"collision_object": collision_object("sheet", 2).serialize().hex(), "planning_scene": planning_scene().serialize().hex()}, sys.stdout)
