#!/usr/bin/python3
"""Writes one malformed recording for the replay's fault tests (Debian's python3-rosbag: /usr/bin/python3).

  make_bad_recording.py KIND - OUT          (the message definitions of ros_msg_defs.py: needs no recording)
  make_bad_recording.py KIND REAL_BAG OUT   (the definitions a real bag holds)

The message classes are built from ROS 1's sensor_msgs definitions (genpy), so the bags are what a ROS 1
recorder writes but for the one fault; truncated is a well-formed bag cut at 60 %. KIND: truncated, no_depth, rgb8, mono8, size_mismatch, short_step, zero_fx, nan_fx; valid, valid_bz2, valid_lz4
(well-formed small bags: the recording fuzz target's seeds).
"""
import os
import sys

import genpy
import genpy.dynamic
import rosbag

kind, real, out = sys.argv[1:4]
truncate = kind == 'truncated'
if truncate:
    kind = 'valid'

if real == '-':
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import ros_msg_defs
    defs = {'sensor_msgs/Image': ros_msg_defs.IMAGE, 'sensor_msgs/CameraInfo': ros_msg_defs.CAMERA_INFO}
else:
    with rosbag.Bag(real) as bag:
        defs = {c.datatype: c.msg_def for c in bag._connections.values()}
Image = genpy.dynamic.generate_dynamic('sensor_msgs/Image', defs['sensor_msgs/Image'])['sensor_msgs/Image']
CameraInfo = genpy.dynamic.generate_dynamic('sensor_msgs/CameraInfo', defs['sensor_msgs/CameraInfo'])['sensor_msgs/CameraInfo']

w, h = 64, 48
info = CameraInfo()
info.header.frame_id = 'camera_depth_optical_frame'
info.width, info.height = w, h
info.distortion_model = 'plumb_bob'
info.D = [0.0] * 5
info.K = [40.0, 0, 31.5, 0, 40.0, 23.5, 0, 0, 1]
info.R = [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]
info.P = [40.0, 0, 31.5, 0, 0, 40.0, 23.5, 0, 0, 0, 1, 0]
image = Image()
image.header.frame_id = 'camera_depth_optical_frame'
image.width, image.height, image.encoding, image.is_bigendian = w, h, '16UC1', 0
image.step = 2 * w
image.data = bytes([0xe8, 0x03]) * (w * h)  # 1000 mm everywhere

if kind == 'rgb8':
    image.encoding, image.step, image.data = 'rgb8', 3 * w, bytes(3 * w * h)
elif kind == 'mono8':
    image.encoding, image.step, image.data = '8UC1', w, bytes(w * h)
elif kind == 'size_mismatch':
    info.width, info.height = 2 * w, 2 * h
elif kind == 'short_step':
    image.step = w  # fewer bytes per row than width x 2
elif kind == 'zero_fx':
    info.K[0] = 0.0
elif kind == 'nan_fx':
    info.K[0] = float('nan')
elif kind not in ('no_depth', 'valid', 'valid_bz2', 'valid_lz4'):
    sys.exit('unknown kind ' + kind)

compression = {'valid_bz2': 'bz2', 'valid_lz4': 'lz4'}.get(kind, 'none')
with rosbag.Bag(out, 'w', compression=compression) as bag:
    for i in range(2):
        t = genpy.Time(1, i * 33333333)
        info.header.stamp = image.header.stamp = t
        bag.write('/camera/depth/camera_info', info, t)
        if kind != 'no_depth':
            bag.write('/camera/depth/image_rect_raw', image, t)

if truncate:
    with open(out, 'r+b') as f:
        f.truncate(int(f.seek(0, 2) * 0.6))
