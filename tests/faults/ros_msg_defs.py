"""ROS 1 message definitions (sensor_msgs/Image, sensor_msgs/CameraInfo with their dependencies, comments
left out) as a ROS 1 recorder stores them in a bag, so that the fault tests write their own bags without a real
recording: genpy.dynamic builds the message classes from these texts (the same MD5 sums as ROS's)."""

IMAGE = """Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
"""

CAMERA_INFO = """Header header
uint32 height
uint32 width
string distortion_model
float64[] D
float64[9]  K
float64[9]  R
float64[12] P
uint32 binning_x
uint32 binning_y
RegionOfInterest roi
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
================================================================================
MSG: sensor_msgs/RegionOfInterest
uint32 x_offset
uint32 y_offset
uint32 height
uint32 width
bool do_rectify
"""
