"""Reading OBJ meshes for the scripts that make geofit's test data and samples."""
from pathlib import Path

import numpy as np


def read_obj(path, triangulate=True):
    """The vertices (n x 3 float64) and faces of an OBJ file, 0-based (negative, relative
    indices resolved; texture and normal indices ignored). Polygons are fanned into triangles
    unless `triangulate` is False; faces are a list of index lists."""
    verts, faces = [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f":
            idx = [int(p.split("/")[0]) for p in parts[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            if triangulate:
                faces.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
            else:
                faces.append(idx)
    return np.array(verts, dtype=np.float64), faces
