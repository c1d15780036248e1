//! `.msg` definitions for MCAP `ros2msg` schemas: the message's own text followed by every
//! dependency, each after a line of 80 `=` and `MSG: pkg/Type`, as rosbag2 writes them.

/// The ROS type name of the reports.
pub(crate) const COLLISION_REPORT_TYPE: &str = "thickness_collision_msgs/msg/CollisionReport";
/// The markers' type.
pub(crate) const MARKER_ARRAY_TYPE: &str = "visualization_msgs/msg/MarkerArray";
/// `/tf` and `/tf_static`.
pub(crate) const TF_MESSAGE_TYPE: &str = "tf2_msgs/msg/TFMessage";
/// `/robot_description`.
pub(crate) const STRING_TYPE: &str = "std_msgs/msg/String";
/// MoveIt's `collision_object` topic.
pub(crate) const COLLISION_OBJECT_TYPE: &str = "moveit_msgs/msg/CollisionObject";
/// MoveIt's `attached_collision_object` topic.
pub(crate) const ATTACHED_COLLISION_OBJECT_TYPE: &str = "moveit_msgs/msg/AttachedCollisionObject";
/// MoveIt's `planning_scene` topic.
pub(crate) const PLANNING_SCENE_TYPE: &str = "moveit_msgs/msg/PlanningScene";
/// MoveIt's `planning_scene_world` topic.
pub(crate) const PLANNING_SCENE_WORLD_TYPE: &str = "moveit_msgs/msg/PlanningSceneWorld";

const SEPARATOR: &str = "================================================================================";

const CONTACT: &str = include_str!("../../interfaces/thickness_collision_msgs/msg/Contact.msg");
const CLEARANCE: &str = include_str!("../../interfaces/thickness_collision_msgs/msg/Clearance.msg");
const COLLISION_REPORT: &str = include_str!("../../interfaces/thickness_collision_msgs/msg/CollisionReport.msg");
const HEADER: &str = "# Standard metadata for higher-level stamped data types.\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
const TIME: &str = "int32 sec\nuint32 nanosec\n";
const POINT: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const VECTOR3: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str = "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";
const POSE: &str = "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n";
const COLOR_RGBA: &str = "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n";
const DURATION: &str = "int32 sec\nuint32 nanosec\n";
const COMPRESSED_IMAGE: &str = "std_msgs/Header header\nstring format\nuint8[] data\n";
const UV_COORDINATE: &str = "float32 u\nfloat32 v\n";
const MESH_FILE: &str = "string filename\nuint8[] data\n";
const MARKER_ARRAY: &str = "visualization_msgs/Marker[] markers\n";
// The Iron/Jazzy layout (texture and mesh file fields), as `crate::msgs::Marker` serialises it.
const MARKER: &str = "int32 ARROW=0
int32 CUBE=1
int32 SPHERE=2
int32 CYLINDER=3
int32 LINE_STRIP=4
int32 LINE_LIST=5
int32 CUBE_LIST=6
int32 SPHERE_LIST=7
int32 POINTS=8
int32 TEXT_VIEW_FACING=9
int32 MESH_RESOURCE=10
int32 TRIANGLE_LIST=11
int32 ARROW_STRIP=12
int32 ADD=0
int32 MODIFY=0
int32 DELETE=2
int32 DELETEALL=3
std_msgs/Header header
string ns
int32 id
int32 type
int32 action
geometry_msgs/Pose pose
geometry_msgs/Vector3 scale
std_msgs/ColorRGBA color
builtin_interfaces/Duration lifetime
bool frame_locked
geometry_msgs/Point[] points
std_msgs/ColorRGBA[] colors
string texture_resource
sensor_msgs/CompressedImage texture
visualization_msgs/UVCoordinate[] uv_coordinates
string text
string mesh_resource
visualization_msgs/MeshFile mesh_file
bool mesh_use_embedded_materials
";
const TF_MESSAGE: &str = "geometry_msgs/TransformStamped[] transforms\n";
const TRANSFORM_STAMPED: &str = "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n";
const TRANSFORM: &str = "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n";
const STRING: &str = "string data\n";
// The planning scene's closure: the upstream files without their comments (moveit_msgs ros2
// branch; common_interfaces humble and jazzy, which agree on these; object_recognition_msgs and
// octomap_msgs ros2 branches), as `crate::msgs::planning_scene` serialises them.
const PLANNING_SCENE: &str = "string name
RobotState robot_state
string robot_model_name
geometry_msgs/TransformStamped[] fixed_frame_transforms
AllowedCollisionMatrix allowed_collision_matrix
LinkPadding[] link_padding
LinkScale[] link_scale
ObjectColor[] object_colors
PlanningSceneWorld world
bool is_diff
";
const PLANNING_SCENE_WORLD: &str = "CollisionObject[] collision_objects\noctomap_msgs/OctomapWithPose octomap\n";
const COLLISION_OBJECT: &str = "std_msgs/Header header
geometry_msgs/Pose pose
string id
object_recognition_msgs/ObjectType type
shape_msgs/SolidPrimitive[] primitives
geometry_msgs/Pose[] primitive_poses
shape_msgs/Mesh[] meshes
geometry_msgs/Pose[] mesh_poses
shape_msgs/Plane[] planes
geometry_msgs/Pose[] plane_poses
string[] subframe_names
geometry_msgs/Pose[] subframe_poses
byte ADD=0
byte REMOVE=1
byte APPEND=2
byte MOVE=3
byte operation
";
const ATTACHED_COLLISION_OBJECT: &str =
    "string link_name\nCollisionObject object\nstring[] touch_links\ntrajectory_msgs/JointTrajectory detach_posture\nfloat64 weight\n";
const ROBOT_STATE: &str = "sensor_msgs/JointState joint_state
sensor_msgs/MultiDOFJointState multi_dof_joint_state
AttachedCollisionObject[] attached_collision_objects
bool is_diff
";
const ALLOWED_COLLISION_MATRIX: &str =
    "string[] entry_names\nAllowedCollisionEntry[] entry_values\nstring[] default_entry_names\nbool[] default_entry_values\n";
const ALLOWED_COLLISION_ENTRY: &str = "bool[] enabled\n";
const LINK_PADDING: &str = "string link_name\nfloat64 padding\n";
const LINK_SCALE: &str = "string link_name\nfloat64 scale\n";
const OBJECT_COLOR: &str = "string id\nstd_msgs/ColorRGBA color\n";
const OBJECT_TYPE: &str = "string key\nstring db\n";
const SOLID_PRIMITIVE: &str = "uint8 BOX=1
uint8 SPHERE=2
uint8 CYLINDER=3
uint8 CONE=4
uint8 PRISM=5
uint8 type
float64[<=3] dimensions
uint8 BOX_X=0
uint8 BOX_Y=1
uint8 BOX_Z=2
uint8 SPHERE_RADIUS=0
uint8 CYLINDER_HEIGHT=0
uint8 CYLINDER_RADIUS=1
uint8 CONE_HEIGHT=0
uint8 CONE_RADIUS=1
uint8 PRISM_HEIGHT=0
geometry_msgs/Polygon polygon
";
const MESH: &str = "MeshTriangle[] triangles\ngeometry_msgs/Point[] vertices\n";
const MESH_TRIANGLE: &str = "uint32[3] vertex_indices\n";
const PLANE: &str = "float64[4] coef\n";
const POLYGON: &str = "Point32[] points\n";
const POINT32: &str = "float32 x\nfloat32 y\nfloat32 z\n";
const TWIST: &str = "Vector3 linear\nVector3 angular\n";
const WRENCH: &str = "Vector3 force\nVector3 torque\n";
const JOINT_STATE: &str = "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n";
const MULTI_DOF_JOINT_STATE: &str =
    "std_msgs/Header header\nstring[] joint_names\ngeometry_msgs/Transform[] transforms\ngeometry_msgs/Twist[] twist\ngeometry_msgs/Wrench[] wrench\n";
const JOINT_TRAJECTORY: &str = "std_msgs/Header header\nstring[] joint_names\nJointTrajectoryPoint[] points\n";
const JOINT_TRAJECTORY_POINT: &str =
    "float64[] positions\nfloat64[] velocities\nfloat64[] accelerations\nfloat64[] effort\nbuiltin_interfaces/Duration time_from_start\n";
const OCTOMAP_WITH_POSE: &str = "std_msgs/Header header\ngeometry_msgs/Pose origin\noctomap_msgs/Octomap octomap\n";
const OCTOMAP: &str = "std_msgs/Header header\nbool binary\nstring id\nfloat64 resolution\nint8[] data\n";

// A collision object's dependencies, in the order they first appear.
const COLLISION_OBJECT_DEPS: [(&str, &str); 12] = [
    ("std_msgs/Header", HEADER),
    ("builtin_interfaces/Time", TIME),
    ("geometry_msgs/Pose", POSE),
    ("geometry_msgs/Point", POINT),
    ("geometry_msgs/Quaternion", QUATERNION),
    ("object_recognition_msgs/ObjectType", OBJECT_TYPE),
    ("shape_msgs/SolidPrimitive", SOLID_PRIMITIVE),
    ("geometry_msgs/Polygon", POLYGON),
    ("geometry_msgs/Point32", POINT32),
    ("shape_msgs/Mesh", MESH),
    ("shape_msgs/MeshTriangle", MESH_TRIANGLE),
    ("shape_msgs/Plane", PLANE),
];

const COLLISION_REPORT_DEPS: [(&str, &str); 6] = [
    ("std_msgs/Header", HEADER),
    ("builtin_interfaces/Time", TIME),
    ("thickness_collision_msgs/Contact", CONTACT),
    ("geometry_msgs/Point", POINT),
    ("geometry_msgs/Vector3", VECTOR3),
    ("thickness_collision_msgs/Clearance", CLEARANCE),
];

const MARKER_ARRAY_DEPS: [(&str, &str); 12] = [
    ("visualization_msgs/Marker", MARKER),
    ("std_msgs/Header", HEADER),
    ("builtin_interfaces/Time", TIME),
    ("geometry_msgs/Pose", POSE),
    ("geometry_msgs/Point", POINT),
    ("geometry_msgs/Quaternion", QUATERNION),
    ("geometry_msgs/Vector3", VECTOR3),
    ("std_msgs/ColorRGBA", COLOR_RGBA),
    ("builtin_interfaces/Duration", DURATION),
    ("sensor_msgs/CompressedImage", COMPRESSED_IMAGE),
    ("visualization_msgs/UVCoordinate", UV_COORDINATE),
    ("visualization_msgs/MeshFile", MESH_FILE),
];

const TF_MESSAGE_DEPS: [(&str, &str); 6] = [
    ("geometry_msgs/TransformStamped", TRANSFORM_STAMPED),
    ("std_msgs/Header", HEADER),
    ("builtin_interfaces/Time", TIME),
    ("geometry_msgs/Transform", TRANSFORM),
    ("geometry_msgs/Vector3", VECTOR3),
    ("geometry_msgs/Quaternion", QUATERNION),
];

const PLANNING_SCENE_DEPS: [(&str, &str); 34] = [
    ("moveit_msgs/RobotState", ROBOT_STATE),
    ("sensor_msgs/JointState", JOINT_STATE),
    ("std_msgs/Header", HEADER),
    ("builtin_interfaces/Time", TIME),
    ("sensor_msgs/MultiDOFJointState", MULTI_DOF_JOINT_STATE),
    ("geometry_msgs/Transform", TRANSFORM),
    ("geometry_msgs/Vector3", VECTOR3),
    ("geometry_msgs/Quaternion", QUATERNION),
    ("geometry_msgs/Twist", TWIST),
    ("geometry_msgs/Wrench", WRENCH),
    ("moveit_msgs/AttachedCollisionObject", ATTACHED_COLLISION_OBJECT),
    ("moveit_msgs/CollisionObject", COLLISION_OBJECT),
    ("geometry_msgs/Pose", POSE),
    ("geometry_msgs/Point", POINT),
    ("object_recognition_msgs/ObjectType", OBJECT_TYPE),
    ("shape_msgs/SolidPrimitive", SOLID_PRIMITIVE),
    ("geometry_msgs/Polygon", POLYGON),
    ("geometry_msgs/Point32", POINT32),
    ("shape_msgs/Mesh", MESH),
    ("shape_msgs/MeshTriangle", MESH_TRIANGLE),
    ("shape_msgs/Plane", PLANE),
    ("trajectory_msgs/JointTrajectory", JOINT_TRAJECTORY),
    ("trajectory_msgs/JointTrajectoryPoint", JOINT_TRAJECTORY_POINT),
    ("builtin_interfaces/Duration", DURATION),
    ("geometry_msgs/TransformStamped", TRANSFORM_STAMPED),
    ("moveit_msgs/AllowedCollisionMatrix", ALLOWED_COLLISION_MATRIX),
    ("moveit_msgs/AllowedCollisionEntry", ALLOWED_COLLISION_ENTRY),
    ("moveit_msgs/LinkPadding", LINK_PADDING),
    ("moveit_msgs/LinkScale", LINK_SCALE),
    ("moveit_msgs/ObjectColor", OBJECT_COLOR),
    ("std_msgs/ColorRGBA", COLOR_RGBA),
    ("moveit_msgs/PlanningSceneWorld", PLANNING_SCENE_WORLD),
    ("octomap_msgs/OctomapWithPose", OCTOMAP_WITH_POSE),
    ("octomap_msgs/Octomap", OCTOMAP),
];

const ATTACHED_COLLISION_OBJECT_AFTER: [(&str, &str); 3] = [
    ("trajectory_msgs/JointTrajectory", JOINT_TRAJECTORY),
    ("trajectory_msgs/JointTrajectoryPoint", JOINT_TRAJECTORY_POINT),
    ("builtin_interfaces/Duration", DURATION),
];

const PLANNING_SCENE_WORLD_AFTER: [(&str, &str); 2] = [("octomap_msgs/OctomapWithPose", OCTOMAP_WITH_POSE), ("octomap_msgs/Octomap", OCTOMAP)];

/// The full `ros2msg` definition of a type this crate writes or reads, or `None`.
pub(crate) fn full_definition(type_name: &str) -> Option<String> {
    // A collision object and its dependencies, then the rest (the two types that hold one).
    let with_object =
        |after: &[(&'static str, &'static str)]| [&[("moveit_msgs/CollisionObject", COLLISION_OBJECT)][..], &COLLISION_OBJECT_DEPS, after].concat();
    let held;
    let (main, deps): (&str, &[(&str, &str)]) = match type_name {
        COLLISION_REPORT_TYPE => (COLLISION_REPORT, &COLLISION_REPORT_DEPS),
        MARKER_ARRAY_TYPE => (MARKER_ARRAY, &MARKER_ARRAY_DEPS),
        TF_MESSAGE_TYPE => (TF_MESSAGE, &TF_MESSAGE_DEPS),
        STRING_TYPE => (STRING, &[]),
        COLLISION_OBJECT_TYPE => (COLLISION_OBJECT, &COLLISION_OBJECT_DEPS),
        ATTACHED_COLLISION_OBJECT_TYPE => {
            held = with_object(&ATTACHED_COLLISION_OBJECT_AFTER);
            (ATTACHED_COLLISION_OBJECT, &held)
        }
        PLANNING_SCENE_WORLD_TYPE => {
            held = with_object(&PLANNING_SCENE_WORLD_AFTER);
            (PLANNING_SCENE_WORLD, &held)
        }
        PLANNING_SCENE_TYPE => (PLANNING_SCENE, &PLANNING_SCENE_DEPS),
        _ => return None,
    };
    let mut out = main.trim_end().to_owned();
    for (name, text) in deps {
        out.push('\n');
        out.push_str(SEPARATOR);
        out.push_str("\nMSG: ");
        out.push_str(name);
        out.push('\n');
        out.push_str(text.trim_end());
    }
    out.push('\n');
    Some(out)
}
