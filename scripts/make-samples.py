"""Makes the demo's bundled samples in www/samples/ from the Stanford scans in ../shared/data.

Run once by hand (the outputs are committed):
    python3 -m venv /tmp/samples && /tmp/samples/bin/pip install numpy fast-simplification
    /tmp/samples/bin/python scripts/make-samples.py [DATA_DIR]

- bunny.obj: stanford-bunny.obj decimated by quadric error (fast-simplification) to about
  2,000 vertices, so the page opens in a blink with a recognisable shape.
- bun000-points.xyz: every 8th point of the raw range scan bun000.ply, as plain x y z text.
"""

from pathlib import Path

import fast_simplification
import numpy as np

import objfile

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "www" / "samples"
TARGET_VERTICES = 2000
POINT_STRIDE = 8


def read_obj(path: Path):
    verts, faces = objfile.read_obj(path)
    return verts, np.array(faces, dtype=np.int64)


def write_bunny(data: Path) -> None:
    verts, faces = read_obj(data / "stanford-bunny.obj")
    used = np.unique(faces)
    remap = np.full(len(verts), -1)
    remap[used] = np.arange(len(used))
    verts, faces = verts[used], remap[faces]
    reduction = 1.0 - TARGET_VERTICES / len(verts)
    v, f = fast_simplification.simplify(verts, faces, target_reduction=reduction)
    lines = ["# Stanford Bunny (Stanford 3D Scanning Repository), decimated by scripts/make-samples.py"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    (OUT / "bunny.obj").write_text("\n".join(lines) + "\n")
    print(f"bunny.obj: {len(v)} vertices, {len(f)} triangles")


def write_points(data: Path) -> None:
    text = (data / "bun000.ply").read_text(errors="replace").splitlines()
    header_end = text.index("end_header")
    count = next(int(l.split()[2]) for l in text if l.startswith("element vertex"))
    rows = [l.split()[:3] for l in text[header_end + 1 : header_end + 1 + count]]
    pts = rows[::POINT_STRIDE]
    body = "\n".join(" ".join(r) for r in pts)
    (OUT / "bun000-points.xyz").write_text(body + "\n")
    print(f"bun000-points.xyz: {len(pts)} points")


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    data = objfile.data_dir()
    write_bunny(data)
    write_points(data)
