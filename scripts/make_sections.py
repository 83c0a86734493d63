#!/usr/bin/env python3
"""Planar sections of triangle meshes as closed polylines (the curve-fitting test data).

Usage: python scripts/make_sections.py MESH.obj AXIS FRACTION OUT.xyz
Intersects the mesh with the plane AXIS = min + FRACTION * (max - min) of its bounding box,
chains the crossing segments into closed loops through shared mesh edges, and writes the
longest loop as two columns (the two other coordinates, in x, y, z order).
"""
import sys
import numpy as np

from objfile import read_obj


def section_loops(verts, faces, axis, level):
    h = verts[:, axis] - level
    # Nudge vertices lying exactly on the plane so every crossing is on an edge interior.
    h[h == 0.0] = 1e-12
    point_of_edge = {}
    adjacency = {}
    for tri in faces:
        crossing = []
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            if (h[a] > 0) != (h[b] > 0):
                key = (min(a, b), max(a, b))
                if key not in point_of_edge:
                    t = h[a] / (h[a] - h[b])
                    point_of_edge[key] = verts[a] + t * (verts[b] - verts[a])
                crossing.append(key)
        if len(crossing) == 2:
            e0, e1 = crossing
            adjacency.setdefault(e0, []).append(e1)
            adjacency.setdefault(e1, []).append(e0)
    loops, seen = [], set()
    for start in adjacency:
        if start in seen:
            continue
        loop, prev, cur = [start], None, start
        seen.add(start)
        while True:
            nxt = [e for e in adjacency[cur] if e != prev and e not in seen]
            if not nxt:
                break
            prev, cur = cur, nxt[0]
            seen.add(cur)
            loop.append(cur)
        closed = start in adjacency[cur] and len(loop) > 2
        loops.append((closed, [point_of_edge[e] for e in loop]))
    return loops


def main():
    mesh, axis, frac, out = sys.argv[1], "xyz".index(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    verts, faces = read_obj(mesh)
    lo, hi = verts[:, axis].min(), verts[:, axis].max()
    level = lo + frac * (hi - lo)
    loops = section_loops(verts, faces, axis, level)
    closed = [pts for c, pts in loops if c]
    best = max(closed, key=len)
    keep = [k for k in range(3) if k != axis]
    pts = np.array(best)[:, keep]
    # Drop points closer than 1e-9 of the diagonal to their predecessor (edge crossings at a
    # shared vertex), so the polyline has no zero-length segments.
    diag = np.linalg.norm(verts.max(0) - verts.min(0))
    kept = [pts[0]]
    for p in pts[1:]:
        if np.linalg.norm(p - kept[-1]) > 1e-9 * diag:
            kept.append(p)
    if np.linalg.norm(kept[0] - kept[-1]) <= 1e-9 * diag:
        kept.pop()
    print(f"{mesh}: {len(loops)} loops ({len(closed)} closed), longest closed {len(kept)} points,"
          f" plane {'xyz'[axis]} = {level:.6g}", file=sys.stderr)
    with open(out, "w") as f:
        for p in kept:
            f.write(f"{p[0]:.9g} {p[1]:.9g}\n")


if __name__ == "__main__":
    main()
