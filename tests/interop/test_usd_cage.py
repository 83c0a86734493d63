#!/usr/bin/env python3
"""geofit's USD cage (`geofit fit --creases --usda out.usda`) opens in Pixar's USD (usd-core).

Fits fandisk (a CAD part with sharp edges) with crease detection on, by Loop and by
Catmull–Clark, writes the cage as USDA and as OBJ with its crease sidecar, opens the layer with
pxr.Usd, and checks that it is a valid stage with one Mesh prim of the right subdivision
scheme, that its faces and points are the OBJ cage's, and that its creases (creaseIndices,
creaseLengths, creaseSharpnesses) are the sidecar's pairs, all edges of the cage and all
infinitely sharp (OpenSubdiv's sharpness 10).

Run: python tests/interop/test_usd_cage.py   (exit status 1 on any failure)
Uses $GEOFIT_BIN, else target/release/geofit (built with cargo if missing).
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from pxr import Usd, UsdGeom

from geofit_cli import REPO, geofit_bin

DATA = REPO.parent / "shared" / "data"
if not DATA.exists():
    DATA = Path("/work/shared/data")


def obj_cage(path):
    """Vertex count and faces (0-based) of an OBJ cage."""
    vertices, faces = 0, []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            vertices += 1
        elif line.startswith("f "):
            faces.append([int(w.split("/")[0]) - 1 for w in line.split()[1:]])
    return vertices, faces


def check(scheme, token, tmp):
    usda, obj = tmp / f"{scheme}.usda", tmp / f"{scheme}.obj"
    cmd = [geofit_bin(), "fit", str(DATA / "fandisk.obj"), "--scheme", scheme, "--creases",
           "--max-iter", "4", "-q", "--usda", str(usda), "--cage", str(obj)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    sidecar = json.loads(obj.with_suffix(".creases.json").read_text())
    stage = Usd.Stage.Open(str(usda))
    assert stage, "the layer does not open"
    mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/cage"))
    assert mesh, "no Mesh prim /cage"
    assert stage.GetDefaultPrim().GetPath() == "/cage"
    assert mesh.GetSubdivisionSchemeAttr().Get() == token
    counts = list(mesh.GetFaceVertexCountsAttr().Get())
    indices = list(mesh.GetFaceVertexIndicesAttr().Get())
    points = mesh.GetPointsAttr().Get()
    vertices, faces = obj_cage(obj)
    assert len(points) == vertices == sidecar["vertices"], (len(points), vertices)
    assert counts == [len(f) for f in faces], "face sizes differ from the OBJ cage"
    assert indices == [v for f in faces for v in f], "faces differ from the OBJ cage"
    ends = list(mesh.GetCreaseIndicesAttr().Get())
    lengths = list(mesh.GetCreaseLengthsAttr().Get())
    sharp = list(mesh.GetCreaseSharpnessesAttr().Get())
    pairs = [tuple(ends[i:i + 2]) for i in range(0, len(ends), 2)]
    assert len(pairs) >= 50, f"only {len(pairs)} crease edges on fandisk's cage"
    assert lengths == [2] * len(pairs) and sharp == [10.0] * len(pairs)
    assert pairs == [tuple(p) for p in sidecar["creases"]], "USD and sidecar creases differ"
    edges = {tuple(sorted((f[k], f[(k + 1) % len(f)]))) for f in faces for k in range(len(f))}
    assert all(p in edges for p in pairs), "a crease pair is no edge of the cage"
    print(f"ok  fandisk {scheme}: {len(faces)} faces, {len(points)} points, {len(pairs)} creases")


def main():
    passed = failed = 0
    with tempfile.TemporaryDirectory() as d:
        for scheme, token in [("loop", "loop"), ("catmull-clark", "catmullClark")]:
            try:
                check(scheme, token, Path(d))
                passed += 1
            except (AssertionError, subprocess.CalledProcessError, OSError) as e:
                print(f"FAIL fandisk {scheme}: {e}")
                failed += 1
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
