//! `.msg` definitions for MCAP `ros2msg` schemas: the message's own text followed by every
//! dependency, each after a line of 80 `=` and `MSG: pkg/Type`, as rosbag2 writes them.

/// The ROS type name of the reports.
pub const COLLISION_REPORT_TYPE: &str = "thickness_collision_msgs/msg/CollisionReport";

const SEPARATOR: &str = "================================================================================";

const CONTACT: &str = include_str!("../../interfaces/thickness_collision_msgs/msg/Contact.msg");
const CLEARANCE: &str = include_str!("../../interfaces/thickness_collision_msgs/msg/Clearance.msg");
const COLLISION_REPORT: &str = include_str!("../../interfaces/thickness_collision_msgs/msg/CollisionReport.msg");
const HEADER: &str = "# Standard metadata for higher-level stamped data types.\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
const TIME: &str = "int32 sec\nuint32 nanosec\n";
const POINT: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const VECTOR3: &str = "float64 x\nfloat64 y\nfloat64 z\n";

/// The full `ros2msg` definition of a type this crate writes, or `None`.
pub fn full_definition(type_name: &str) -> Option<String> {
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
