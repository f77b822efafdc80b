"""The ROS 2 message definitions the MCAP export embeds (ROS 2 Humble's, as ``ros2 msg show``
writes them), by type name: each a schema of the file, its own fields followed by every type
it uses, so a reader needs no ROS installation to decode it."""

_SEPARATOR = "=" * 80 + "\n"

#: each type's own fields
# fmt: off
_FIELDS: dict[str, str] = {
    "tf2_msgs/TFMessage": (
        'geometry_msgs/TransformStamped[] transforms\n'
    ),
    "geometry_msgs/TransformStamped": (
        'std_msgs/Header header\n'
        'string child_frame_id\n'
        'geometry_msgs/Transform transform\n'
    ),
    "std_msgs/Header": (
        'builtin_interfaces/Time stamp\n'
        'string frame_id\n'
    ),
    "builtin_interfaces/Time": (
        'int32 sec\n'
        'uint32 nanosec\n'
    ),
    "geometry_msgs/Transform": (
        'geometry_msgs/Vector3 translation\n'
        'geometry_msgs/Quaternion rotation\n'
    ),
    "geometry_msgs/Vector3": (
        'float64 x\n'
        'float64 y\n'
        'float64 z\n'
    ),
    "geometry_msgs/Quaternion": (
        'float64 x\n'
        'float64 y\n'
        'float64 z\n'
        'float64 w\n'
    ),
    "sensor_msgs/JointState": (
        'std_msgs/Header header\n'
        'string[] name\n'
        'float64[] position\n'
        'float64[] velocity\n'
        'float64[] effort\n'
    ),
    "geometry_msgs/WrenchStamped": (
        'std_msgs/Header header\n'
        'geometry_msgs/Wrench wrench\n'
    ),
    "geometry_msgs/Wrench": (
        'geometry_msgs/Vector3 force\n'
        'geometry_msgs/Vector3 torque\n'
    ),
    "nav_msgs/Odometry": (
        'std_msgs/Header header\n'
        'string child_frame_id\n'
        'geometry_msgs/PoseWithCovariance pose\n'
        'geometry_msgs/TwistWithCovariance twist\n'
    ),
    "geometry_msgs/PoseWithCovariance": (
        'geometry_msgs/Pose pose\n'
        'float64[36] covariance\n'
    ),
    "geometry_msgs/Pose": (
        'geometry_msgs/Point position\n'
        'geometry_msgs/Quaternion orientation\n'
    ),
    "geometry_msgs/Point": (
        'float64 x\n'
        'float64 y\n'
        'float64 z\n'
    ),
    "geometry_msgs/TwistWithCovariance": (
        'geometry_msgs/Twist twist\n'
        'float64[36] covariance\n'
    ),
    "geometry_msgs/Twist": (
        'geometry_msgs/Vector3 linear\n'
        'geometry_msgs/Vector3 angular\n'
    ),
    "sensor_msgs/Imu": (
        'std_msgs/Header header\n'
        'geometry_msgs/Quaternion orientation\n'
        'float64[9] orientation_covariance\n'
        'geometry_msgs/Vector3 angular_velocity\n'
        'float64[9] angular_velocity_covariance\n'
        'geometry_msgs/Vector3 linear_acceleration\n'
        'float64[9] linear_acceleration_covariance\n'
    ),
    "sensor_msgs/FluidPressure": (
        'std_msgs/Header header\n'
        'float64 fluid_pressure\n'
        'float64 variance\n'
    ),
    "visualization_msgs/MarkerArray": (
        'visualization_msgs/Marker[] markers\n'
    ),
    "visualization_msgs/Marker": (
        'int32 ARROW=0\n'
        'int32 CUBE=1\n'
        'int32 SPHERE=2\n'
        'int32 CYLINDER=3\n'
        'int32 LINE_STRIP=4\n'
        'int32 LINE_LIST=5\n'
        'int32 CUBE_LIST=6\n'
        'int32 SPHERE_LIST=7\n'
        'int32 POINTS=8\n'
        'int32 TEXT_VIEW_FACING=9\n'
        'int32 MESH_RESOURCE=10\n'
        'int32 TRIANGLE_LIST=11\n'
        'int32 ADD=0\n'
        'int32 MODIFY=0\n'
        'int32 DELETE=2\n'
        'int32 DELETEALL=3\n'
        'std_msgs/Header header\n'
        'string ns\n'
        'int32 id\n'
        'int32 type\n'
        'int32 action\n'
        'geometry_msgs/Pose pose\n'
        'geometry_msgs/Vector3 scale\n'
        'std_msgs/ColorRGBA color\n'
        'builtin_interfaces/Duration lifetime\n'
        'bool frame_locked\n'
        'geometry_msgs/Point[] points\n'
        'std_msgs/ColorRGBA[] colors\n'
        'string texture_resource\n'
        'sensor_msgs/CompressedImage texture\n'
        'visualization_msgs/UVCoordinate[] uv_coordinates\n'
        'string text\n'
        'string mesh_resource\n'
        'visualization_msgs/MeshFile mesh_file\n'
        'bool mesh_use_embedded_materials\n'
    ),
    "std_msgs/ColorRGBA": (
        'float32 r\n'
        'float32 g\n'
        'float32 b\n'
        'float32 a\n'
    ),
    "builtin_interfaces/Duration": (
        'int32 sec\n'
        'uint32 nanosec\n'
    ),
    "sensor_msgs/CompressedImage": (
        'std_msgs/Header header\n'
        'string format\n'
        'uint8[] data\n'
    ),
    "visualization_msgs/UVCoordinate": (
        'float32 u\n'
        'float32 v\n'
    ),
    "sensor_msgs/Image": (
        'std_msgs/Header header\n'
        'uint32 height\n'
        'uint32 width\n'
        'string encoding\n'
        'uint8 is_bigendian\n'
        'uint32 step\n'
        'uint8[] data\n'
    ),
    "sensor_msgs/CameraInfo": (
        'std_msgs/Header header\n'
        'uint32 height\n'
        'uint32 width\n'
        'string distortion_model\n'
        'float64[] d\n'
        'float64[9] k\n'
        'float64[9] r\n'
        'float64[12] p\n'
        'uint32 binning_x\n'
        'uint32 binning_y\n'
        'sensor_msgs/RegionOfInterest roi\n'
    ),
    "sensor_msgs/RegionOfInterest": (
        'uint32 x_offset\n'
        'uint32 y_offset\n'
        'uint32 height\n'
        'uint32 width\n'
        'bool do_rectify\n'
    ),
    "sensor_msgs/LaserScan": (
        'std_msgs/Header header\n'
        'float32 angle_min\n'
        'float32 angle_max\n'
        'float32 angle_increment\n'
        'float32 time_increment\n'
        'float32 scan_time\n'
        'float32 range_min\n'
        'float32 range_max\n'
        'float32[] ranges\n'
        'float32[] intensities\n'
    ),
    "visualization_msgs/MeshFile": (
        'string filename\n'
        'uint8[] data\n'
    ),
    "sensor_msgs/Range": (
        'std_msgs/Header header\n'
        'uint8 ULTRASOUND=0\n'
        'uint8 INFRARED=1\n'
        'uint8 radiation_type\n'
        'float32 field_of_view\n'
        'float32 min_range\n'
        'float32 max_range\n'
        'float32 range\n'
    ),
}
# fmt: on

#: the types a message uses, in the order its definition lists them
_USES: dict[str, tuple[str, ...]] = {
    "tf2_msgs/TFMessage": (
        "geometry_msgs/TransformStamped",
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/Transform",
        "geometry_msgs/Vector3",
        "geometry_msgs/Quaternion",
    ),
    "sensor_msgs/JointState": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
    ),
    "geometry_msgs/WrenchStamped": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/Wrench",
        "geometry_msgs/Vector3",
    ),
    "nav_msgs/Odometry": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion",
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist",
        "geometry_msgs/Vector3",
    ),
    "sensor_msgs/Imu": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/Quaternion",
        "geometry_msgs/Vector3",
    ),
    "sensor_msgs/FluidPressure": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
    ),
    "sensor_msgs/Image": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
    ),
    "sensor_msgs/CameraInfo": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "sensor_msgs/RegionOfInterest",
    ),
    "sensor_msgs/LaserScan": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
    ),
    "sensor_msgs/Range": (
        "std_msgs/Header",
        "builtin_interfaces/Time",
    ),
    "visualization_msgs/MarkerArray": (
        "visualization_msgs/Marker",
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion",
        "geometry_msgs/Vector3",
        "std_msgs/ColorRGBA",
        "builtin_interfaces/Duration",
        "sensor_msgs/CompressedImage",
        "visualization_msgs/UVCoordinate",
        "visualization_msgs/MeshFile",
    ),
}


def _definition(name: str) -> str:
    return _FIELDS[name] + "".join(
        f"{_SEPARATOR}MSG: {used}\n{_FIELDS[used]}" for used in _USES[name]
    )


#: the full definition of each message type the bag holds
MESSAGE_DEFINITIONS: dict[str, str] = {name: _definition(name) for name in _USES}
