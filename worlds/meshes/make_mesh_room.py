#!/usr/bin/env python3
"""Writes the meshes of worlds/mesh_room.xml, as a building scan and a product model would come:

  mesh_room.obj        the room's walls, y up (as most scan exports), metres, origin at the outer corner; outer
                       6.2 x 3.2 m, walls 0.1 m thick and 2.4 m high, a 0.9 m door gap in one long wall. Each wall
                       is a closed box whose faces are split into cells of at most 1 m (a scan has many triangles).
  mesh_room_table.stl  a table (binary STL), z up, origin under its centre: a 1.0 x 0.6 m top 0.04 m thick at
                       0.71..0.75 m on four 0.05 m legs.

Every box is closed and outward-facing, and no two overlap, so the meshes are closed (exact solid truth).
Run: python3 worlds/meshes/make_mesh_room.py (writes beside itself; the output is deterministic).
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def box_faces(lo, hi, cell):
    """Triangles (three (x, y, z) tuples each, counter-clockwise seen from outside) of the box lo..hi, each face
    split into a grid of at most `cell` metres; edges shared by two faces are split alike."""
    n = [max(1, math.ceil((hi[i] - lo[i]) / cell - 1e-9)) for i in range(3)]
    tris = []
    for a in range(3):
        u, v = (a + 1) % 3, (a + 2) % 3
        for side in (lo[a], hi[a]):
            outward = 1 if side == hi[a] else -1
            for i in range(n[u]):
                for j in range(n[v]):
                    def p(ii, jj):
                        q = [0.0, 0.0, 0.0]
                        q[a] = side
                        q[u] = lo[u] + (hi[u] - lo[u]) * ii / n[u]
                        q[v] = lo[v] + (hi[v] - lo[v]) * jj / n[v]
                        return tuple(round(c, 6) for c in q)
                    quad = [p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]  # normal along +a
                    if outward < 0:
                        quad.reverse()
                    tris.append((quad[0], quad[1], quad[2]))
                    tris.append((quad[0], quad[2], quad[3]))
    return tris


def write_obj(path, boxes, comment):
    """Each box's triangles with its own vertices: boxes that touch share no vertex, so no edge is used twice in
    one direction (MuJoCo refuses that as "faces have inconsistent orientation")."""
    verts, faces = [], []
    for tris in boxes:
        index = {}
        for t in tris:
            f = []
            for p in t:
                if p not in index:
                    index[p] = len(verts) + 1
                    verts.append(p)
                f.append(index[p])
            faces.append(f)
    with open(path, "w") as out:
        out.write("# " + comment + "\n")
        for v in verts:
            out.write("v %.6f %.6f %.6f\n" % v)
        for f in faces:
            out.write("f %d %d %d\n" % tuple(f))
    return len(faces)


def write_stl(path, tris, comment):
    with open(path, "wb") as out:
        out.write(comment.encode()[:80].ljust(80, b" "))
        out.write(struct.pack("<I", len(tris)))
        for a, b, c in tris:
            e1 = [b[i] - a[i] for i in range(3)]
            e2 = [c[i] - a[i] for i in range(3)]
            n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            out.write(struct.pack("<3f", *[x / length for x in n]))
            for p in (a, b, c):
                out.write(struct.pack("<3f", *p))
            out.write(struct.pack("<H", 0))
    return len(tris)


def main():
    # The room, y up: x 0..6.2 along the long walls, z 0..3.2 across, y 0..2.4 up. The long walls run the whole
    # length; the short ones fit between them; the long wall at z 3.1..3.2 has the door gap at x 2.7..3.6.
    h, t = 2.4, 0.1
    walls = [((0.0, 0.0, 0.0), (6.2, h, t)),                 # long wall (north once placed)
             ((0.0, 0.0, 3.2 - t), (2.7, h, 3.2)),           # long wall with the door gap (south): west part
             ((3.6, 0.0, 3.2 - t), (6.2, h, 3.2)),           # east part
             ((0.0, 0.0, t), (t, h, 3.2 - t)),               # short wall (west)
             ((6.2 - t, 0.0, t), (6.2, h, 3.2 - t))]         # short wall (east)
    room = [box_faces(lo, hi, 1.0) for lo, hi in walls]
    n_room = write_obj(os.path.join(HERE, "mesh_room.obj"), room,
                       "stvl-bench mesh_room: walls of a 6 x 3 m room (y up, metres), by make_mesh_room.py")
    # The table, z up, origin on the floor under its centre.
    top = ((-0.5, -0.3, 0.71), (0.5, 0.3, 0.75))
    legs = [((sx * 0.45 - 0.025, sy * 0.25 - 0.025, 0.0), (sx * 0.45 + 0.025, sy * 0.25 + 0.025, 0.71))
            for sx in (-1, 1) for sy in (-1, 1)]
    table = [tri for lo, hi in [top] + legs for tri in box_faces(lo, hi, 0.5)]
    n_table = write_stl(os.path.join(HERE, "mesh_room_table.stl"), table, "stvl-bench mesh_room table, by make_mesh_room.py")
    print("mesh_room.obj: %d triangles; mesh_room_table.stl: %d triangles" % (n_room, n_table))


if __name__ == "__main__":
    main()
