#!/usr/bin/python3
"""Independent figures of a bag's depth topic, for tests/recording (Debian's python3-rosbag: /usr/bin/python3).

Usage: /usr/bin/python3 depth_stats.py BAG DEPTH_TOPIC UNIT_M
Prints one line per 16-bit depth image: "frame STAMP_S WIDTH HEIGHT VALID_COUNT MIN_M MAX_M".
"""
import array
import sys

import rosbag

bag_path, topic, unit_m = sys.argv[1], sys.argv[2], float(sys.argv[3])
with rosbag.Bag(bag_path) as bag:
    for _, msg, _ in bag.read_messages(topics=[topic]):
        values = array.array('H')
        for v in range(msg.height):
            values.frombytes(bytes(msg.data[v * msg.step:v * msg.step + 2 * msg.width]))
        if bool(msg.is_bigendian) != (sys.byteorder == 'big'):
            values.byteswap()
        valid = [d for d in values if d > 0]
        print('frame %.9f %d %d %d %.6f %.6f' % (msg.header.stamp.to_sec(), msg.width, msg.height, len(valid),
                                                 min(valid) * unit_m, max(valid) * unit_m))
