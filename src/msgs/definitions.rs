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

/// The full `ros2msg` definition of a type this crate writes, or `None`.
pub(crate) fn full_definition(type_name: &str) -> Option<String> {
    let (main, deps): (&str, &[(&str, &str)]) = match type_name {
        COLLISION_REPORT_TYPE => (
            COLLISION_REPORT,
            &[
                ("std_msgs/Header", HEADER),
                ("builtin_interfaces/Time", TIME),
                ("thickness_collision_msgs/Contact", CONTACT),
                ("geometry_msgs/Point", POINT),
                ("geometry_msgs/Vector3", VECTOR3),
                ("thickness_collision_msgs/Clearance", CLEARANCE),
            ],
        ),
        MARKER_ARRAY_TYPE => (
            MARKER_ARRAY,
            &[
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
            ],
        ),
        TF_MESSAGE_TYPE => (
            TF_MESSAGE,
            &[
                ("geometry_msgs/TransformStamped", TRANSFORM_STAMPED),
                ("std_msgs/Header", HEADER),
                ("builtin_interfaces/Time", TIME),
                ("geometry_msgs/Transform", TRANSFORM),
                ("geometry_msgs/Vector3", VECTOR3),
                ("geometry_msgs/Quaternion", QUATERNION),
            ],
        ),
        STRING_TYPE => (STRING, &[]),
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
