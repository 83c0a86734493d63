"""Helpers shared by the scripts that make geofit's test data and samples: where the source
scans are, and reading OBJ meshes."""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def data_dir() -> Path:
    """The folder of the source scans: the first command-line argument, else ../shared/data
    beside the checkout, else /work/shared/data."""
    if len(sys.argv) > 1:
        return Path(sys.argv[1])
    beside = ROOT.parent / "shared" / "data"
    return beside if beside.is_dir() else Path("/work/shared/data")


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
