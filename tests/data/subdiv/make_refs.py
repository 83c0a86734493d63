"""Regenerates the subdivision reference data in this directory.

Not run in CI. Run it with GEOFIT_REGEN_SUBDIV_REFS=1 after `pip install pymeshlab bpy`:

    GEOFIT_REGEN_SUBDIV_REFS=1 python3 tests/data/subdiv/make_refs.py        # everything
    GEOFIT_REGEN_SUBDIV_REFS=1 python3 tests/data/subdiv/make_refs.py loop   # the Loop outputs

Inputs are small cut-outs / decimations of the shared scans (../shared/data):
- bunny_patch.obj: 160 faces grown from one face of stanford-bunny.obj (open, with boundary);
- spot_coarse.obj: spot.obj decimated by MeshLab's quadric edge collapse to 200 faces (closed);
- spot_quads.obj, bunny_quads.obj: those with triangle pairs merged into quads where possible
  (quad-dominant: a few triangles remain).
Outputs (Loop by MeshLab's Loop subdivision with Loop's weights, Catmull–Clark by Blender's
OpenSubdiv modifier):
- *_loop2.obj: two Loop steps (pymeshlab `meshing_surface_subdivision_loop`, weights 'Loop',
  threshold 0 so every edge is split; libigl's igl.loop uses Warren's simplified weights);
- *_cc2.obj: two Catmull–Clark steps (Blender 5.0 subsurf = OpenSubdiv, boundary smooth 'ALL',
  no limit surface). Blender stores float32 coordinates, so these agree to about 1e-7 only.
pymeshlab's "Catmull-Clark" was tried and is not the standard scheme (interior vertices differ
and boundary vertices move inward), so it is not used. No installable library offers Doo–Sabin;
it is tested against analytic properties instead (tests/subdiv_doo_sabin.rs).
"""
import os
import sys
from collections import defaultdict, deque

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "scripts"))
import objfile  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.environ.get("GEOFIT_DATA", os.path.join(HERE, "..", "..", "..", "..", "shared", "data"))
if not os.path.isdir(DATA):
    DATA = "/work/shared/data"


def read_obj(path):
    """Vertices and polygons (not triangulated) of an OBJ file."""
    return objfile.read_obj(path, triangulate=False)


def write_obj(path, V, F):
    with open(path, "w") as f:
        for v in V:
            f.write("v %.17g %.17g %.17g\n" % tuple(v))
        for face in F:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def manifold(F):
    edges = defaultdict(int)
    for f in F:
        for i in range(len(f)):
            a, b = f[i], f[(i + 1) % len(f)]
            edges[(a, b)] += 1
    if any(c > 1 for c in edges.values()):
        return False
    # each vertex: one fan
    out = defaultdict(list)
    for f in F:
        for i in range(len(f)):
            out[f[i]].append((f[i - 1], f[(i + 1) % len(f)]))
    for v, wedges in out.items():
        nxt = {prev: nx for prev, nx in wedges}
        starts = [p for p, _ in wedges if (v, p) not in edges] or [wedges[0][0]]
        if len(starts) > 1:
            return False
    return True


def compact(V, F):
    used = sorted({i for f in F for i in f})
    remap = {o: n for n, o in enumerate(used)}
    return V[used], [[remap[i] for i in f] for f in F]


def grow(V, F, seed, count):
    adj = defaultdict(list)
    for fi, f in enumerate(F):
        for i in range(3):
            adj[frozenset((f[i], f[(i + 1) % 3]))].append(fi)
    seen, order, queue = {seed}, [], deque([seed])
    while queue and len(order) < count:
        fi = queue.popleft()
        order.append(fi)
        f = F[fi]
        for i in range(3):
            for g in adj[frozenset((f[i], f[(i + 1) % 3]))]:
                if g not in seen:
                    seen.add(g)
                    queue.append(g)
    return compact(V, [F[i] for i in order])


def quads_from_pairs(F):
    """Greedy: merge each triangle with an unmerged neighbour across its longest shared edge."""
    edge_face = {}
    for fi, f in enumerate(F):
        for i in range(3):
            edge_face[(f[i], f[(i + 1) % 3])] = fi
    used, out = set(), []
    for fi, f in enumerate(F):
        if fi in used:
            continue
        for i in range(3):
            a, b, c = f[i], f[(i + 1) % 3], f[(i + 2) % 3]
            g = edge_face.get((b, a))
            if g is not None and g not in used and g != fi:
                d = [x for x in F[g] if x not in (a, b)][0]
                used.update((fi, g))
                out.append([a, d, b, c])
                break
        else:
            used.add(fi)
            out.append(list(f))
    return out


def main():
    if os.environ.get("GEOFIT_REGEN_SUBDIV_REFS") != "1":
        sys.exit("set GEOFIT_REGEN_SUBDIV_REFS=1 to regenerate the reference data")
    import pymeshlab

    V, F = read_obj(os.path.join(DATA, "stanford-bunny.obj"))
    for count in range(160, 120, -1):
        Vp, Fp = grow(V, F, 30000, count)
        if manifold(Fp):
            break
    write_obj(os.path.join(HERE, "bunny_patch.obj"), Vp, Fp)
    write_obj(os.path.join(HERE, "bunny_quads.obj"), Vp, quads_from_pairs(Fp))

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(os.path.join(DATA, "spot.obj"))
    ms.meshing_decimation_quadric_edge_collapse(targetfacenum=200, preservetopology=True)
    m = ms.current_mesh()
    Vs, Fs = m.vertex_matrix(), [list(map(int, f)) for f in m.face_matrix()]
    Vs, Fs = compact(Vs, Fs)
    write_obj(os.path.join(HERE, "spot_coarse.obj"), Vs, Fs)
    write_obj(os.path.join(HERE, "spot_quads.obj"), Vs, quads_from_pairs(Fs))

    make_loop_refs()

    try:
        make_cc_refs()
    except ImportError:
        print("bpy not installed: Catmull–Clark references not regenerated")


def make_loop_refs():
    import pymeshlab

    for name in ["bunny_patch", "spot_coarse"]:
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(os.path.join(HERE, name + ".obj"))
        ms.meshing_surface_subdivision_loop(
            loopweight="Loop", iterations=2, threshold=pymeshlab.PercentageValue(0)
        )
        m = ms.current_mesh()
        Fo = [list(map(int, f)) for f in m.face_matrix()]
        write_obj(os.path.join(HERE, name + "_loop2.obj"), m.vertex_matrix(), Fo)


def make_cc_refs():
    import bpy

    for name in ["spot_quads", "bunny_quads"]:
        V, F = read_obj(os.path.join(HERE, name + ".obj"))
        bpy.ops.wm.read_factory_settings(use_empty=True)
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(V.tolist(), [], F)
        obj = bpy.data.objects.new(name, mesh)
        bpy.context.collection.objects.link(obj)
        mod = obj.modifiers.new("cc", "SUBSURF")
        mod.levels = 2
        mod.render_levels = 2
        mod.subdivision_type = "CATMULL_CLARK"
        mod.boundary_smooth = "ALL"
        mod.use_limit_surface = False
        mod.use_creases = False
        mod.uv_smooth = "NONE"
        dg = bpy.context.evaluated_depsgraph_get()
        ev = obj.evaluated_get(dg)
        m = ev.to_mesh()
        Vo = np.array([v.co[:] for v in m.vertices])
        Fo = [list(p.vertices) for p in m.polygons]
        write_obj(os.path.join(HERE, name + "_cc2.obj"), Vo, Fo)


if __name__ == "__main__":
    if sys.argv[1:] == ["loop"]:
        if os.environ.get("GEOFIT_REGEN_SUBDIV_REFS") != "1":
            sys.exit("set GEOFIT_REGEN_SUBDIV_REFS=1 to regenerate the reference data")
        make_loop_refs()
    else:
        main()
