#!/usr/bin/python3
"""Compares the first depth images of a bag with 16-bit PNGs (depth_00000.png, ...) written by `stvl-bench render`.

Usage: compare_bag_depth.py BAG RENDER_DIR. Exit 0 when every PNG equals the bag's image of the same index.
Decodes only what stvl-bench writes (16-bit greyscale, non-interlaced) with zlib, since /usr/bin/python3 has no
numpy or PIL.
"""
import glob
import os
import struct
import sys
import zlib

import rosbag


def read_png16(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 16 and color == 0 and interlace == 0, "expected 16-bit grey"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw, stride, bpp = zlib.decompress(idat), width * 2, 2
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return struct.unpack(">%dH" % (width * height), b"".join(rows))


def main():
    bag_path, render_dir = sys.argv[1], sys.argv[2]
    pngs = sorted(p for p in glob.glob(os.path.join(render_dir, "depth_*.png")) if not p.endswith("_color.png"))
    images = []
    with rosbag.Bag(bag_path) as bag:
        for _, msg, _ in bag.read_messages(topics=["/camera/depth/image_rect_raw"]):
            images.append(struct.unpack("<%dH" % (msg.width * msg.height), msg.data) if not msg.is_bigendian else None)
            if len(images) == len(pngs):
                break
    if not pngs or len(images) < len(pngs):
        print("FAIL: %d PNGs, %d bag images" % (len(pngs), len(images)))
        return 1
    for path, image in zip(pngs, images):
        png = read_png16(path)
        diff = sum(1 for a, b in zip(png, image) if a != b)
        if diff:
            print("FAIL: %s differs from the bag's image in %d pixels" % (os.path.basename(path), diff))
            return 1
    print("bag depth images equal %d rendered frames" % len(pngs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
