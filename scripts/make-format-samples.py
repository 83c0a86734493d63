"""Makes the small scanner-format test files in tests/data/formats/ with the formats' own Python
writers, and tests/data/formats/expected.json with what each file holds, for the Rust tests.

Run by hand from the repository root (the outputs are committed):
    python3 -m venv .venv && .venv/bin/pip install numpy -r scripts/bench-requirements.txt
    .venv/bin/python scripts/make-format-samples.py [DATA_DIR]

DATA_DIR defaults to ../shared/data (else /work/shared/data). Sources: bun000.ply (a Cyberware
range scan of the Stanford Bunny with its 512 x 400 range grid) and stanford-bunny.obj, both from
the Stanford 3D Scanning Repository; suzanne.obj (Blender's test monkey) from corpus/.

What each file is (all coordinates are stored as the files store them, so the expected values
below are computed from exactly the stored numbers, in f64):
- bun000-grid.e57 (pye57): one structured scan, bun000's grid sampled every 10th column and
  row (52 x 40 cells), every cell written with rowIndex/columnIndex, the empty ones with
  cartesianInvalidState = 2; a pose (rotation quaternion + translation).
- two-scans.e57 (pye57): that kind of scan every 20th column/row, plus an unstructured scan
  (every 97th bunny vertex, with intensity and colour), each with its own pose.
- bunny.las / bunny.laz (laspy, lazrs): every 45th bunny vertex, LAS 1.2 point format 3,
  scale 1e-6 and an offset; the LAZ is the same points compressed. bunny-14.las: LAS 1.4
  point format 6 (64-bit point counts).
- bunny-ascii.pcd / bunny-binary.pcd / bunny-compressed.pcd (pypcd4): every 45th bunny vertex
  with extra fields in different orders and types (rgb, intensity, a u16 ring, an f64 time).
- bun000-grid.ptx (written here, PTX is plain text): bun000 every 10th column and row, column
  by column as PTX orders them, empty cells as "0 0 0 0.5 0 0 0", with a 4 x 4 pose.
  two-scans.ptx: two scans (every 20th column/row) with different poses, the second without
  colour columns.
- bunny.pts: Leica PTS, a count line then "x y z intensity r g b".
- suzanne-scene.glb (pygltflib): Suzanne (triangulated) under a node hierarchy with
  translation / rotation / scale and a matrix, instanced twice; a second mesh with a triangle
  strip, a fan, a point and a line primitive; a node outside the scene (not read).
- suzanne-embedded.gltf (pygltflib): JSON with the buffer as a base64 data: URI, positions
  interleaved with normals (byteStride 24), u32 indices, a node matrix.
"""

import json
import struct
from pathlib import Path

import laspy
import numpy as np
import pye57
import pygltflib
from pypcd4 import Encoding, PointCloud
import objfile

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "data" / "formats"


def read_bun000(path: Path):
    """Vertices (float32 as stored, widened to f64) and the range grid (cols, rows, cells)."""
    lines = path.read_text().splitlines()
    cols = rows = None
    n_vertex = n_grid = None
    i = 0
    while lines[i] != "end_header":
        parts = lines[i].split()
        if parts[:2] == ["obj_info", "num_cols"]:
            cols = int(parts[2])
        if parts[:2] == ["obj_info", "num_rows"]:
            rows = int(parts[2])
        if parts[:2] == ["element", "vertex"]:
            n_vertex = int(parts[2])
        if parts[:2] == ["element", "range_grid"]:
            n_grid = int(parts[2])
        i += 1
    body = lines[i + 1 :]
    verts = np.array([[float(x) for x in l.split()] for l in body[:n_vertex]], dtype=np.float32)
    cells = []
    for l in body[n_vertex : n_vertex + n_grid]:
        p = l.split()
        cells.append(int(p[1]) if p[0] != "0" else -1)
    grid = np.array(cells, dtype=np.int64).reshape(rows, cols)
    return verts.astype(np.float64), grid


def read_obj(path: Path):
    verts, faces = objfile.read_obj(path)
    return verts, np.array(faces, dtype=np.uint32)


def f32(a):
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def quat_matrix(w, x, y, z):
    """Rotation matrix of a unit quaternion (w, x, y, z), column-vector convention."""
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def unit_quat(axis, degrees):
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    h = np.radians(degrees) / 2
    return np.array([np.cos(h), *(np.sin(h) * axis)])


def summary(points, triangles=0, scans=None, grid=None, cells=None):
    """What the Rust tests compare: counts, bounding box, coordinate sums and a few points."""
    p = np.asarray(points, dtype=np.float64)
    out = {
        "points": int(len(p)),
        "triangles": int(triangles),
        "bbox_min": p.min(axis=0).tolist(),
        "bbox_max": p.max(axis=0).tolist(),
        "sum": p.sum(axis=0).tolist(),
        "first": p[0].tolist(),
        "last": p[-1].tolist(),
    }
    if scans is not None:
        out["scans"] = scans
    out["grid"] = grid
    if cells is not None:
        out["cells"] = cells
    return out


def subgrid(grid, stride):
    """Every `stride`-th column and row of the bun000 grid: cell (c, r) -> vertex or -1."""
    return grid[::stride, ::stride]


# ---------------------------------------------------------------------------------------- E57


def e57_scan(verts, sub, quat, trans):
    """Structured scan data: every cell, invalid ones flagged; and the valid world points."""
    rows, cols = sub.shape
    r_idx, c_idx = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    idx = sub.reshape(-1)
    valid = idx >= 0
    local = np.zeros((rows * cols, 3))
    local[valid] = verts[idx[valid]]
    local = f32(local)  # pye57 stores single precision
    data = {
        "cartesianX": local[:, 0].astype(np.float32),
        "cartesianY": local[:, 1].astype(np.float32),
        "cartesianZ": local[:, 2].astype(np.float32),
        "rowIndex": r_idx.reshape(-1).astype(np.uint16),
        "columnIndex": c_idx.reshape(-1).astype(np.uint16),
        "cartesianInvalidState": np.where(valid, 0, 2).astype(np.int8),
    }
    rot = quat_matrix(*quat)
    world = local[valid] @ rot.T + trans
    cell_rc = np.stack([c_idx.reshape(-1)[valid], r_idx.reshape(-1)[valid]], axis=1)
    return data, world, cell_rc, (cols, rows)


def sample_cells(world, cell_rc, picks):
    out = []
    for k in picks:
        c, r = cell_rc[k]
        out.append([int(c), int(r), *world[k].tolist()])
    return out


def write_e57(verts, grid, bunny, expected):
    quat = unit_quat([0.3, -0.2, 1.0], 35.0)
    trans = np.array([1.5, -2.0, 0.25])
    data, world, cell_rc, size = e57_scan(verts, subgrid(grid, 10), quat, trans)
    path = OUT / "bun000-grid.e57"
    path.unlink(missing_ok=True)
    with pye57.E57(str(path), mode="w") as e:
        e.write_scan_raw(data, rotation=quat, translation=trans, name="bun000 every 10th")
    picks = [0, len(world) // 2, len(world) - 1]
    expected[path.name] = summary(
        world, scans=1, grid=list(size), cells=sample_cells(world, cell_rc, picks)
    )

    quat_a = unit_quat([1.0, 0.0, 0.0], -20.0)
    trans_a = np.array([0.0, 0.5, 0.0])
    data_a, world_a, _, _ = e57_scan(verts, subgrid(grid, 20), quat_a, trans_a)
    sel = bunny[::97]
    local_b = f32(sel)
    quat_b = unit_quat([0.0, 1.0, 0.0], 90.0)
    trans_b = np.array([-1.0, 0.0, 3.0])
    n = len(local_b)
    data_b = {
        "cartesianX": local_b[:, 0].astype(np.float32),
        "cartesianY": local_b[:, 1].astype(np.float32),
        "cartesianZ": local_b[:, 2].astype(np.float32),
        "intensity": np.linspace(0.1, 0.9, n).astype(np.float32),
        "colorRed": (np.arange(n) % 256).astype(np.uint8),
        "colorGreen": np.full(n, 128, dtype=np.uint8),
        "colorBlue": np.full(n, 7, dtype=np.uint8),
    }
    world_b = local_b @ quat_matrix(*quat_b).T + trans_b
    path = OUT / "two-scans.e57"
    path.unlink(missing_ok=True)
    with pye57.E57(str(path), mode="w") as e:
        e.write_scan_raw(data_a, rotation=quat_a, translation=trans_a, name="structured")
        e.write_scan_raw(data_b, rotation=quat_b, translation=trans_b, name="unstructured")
    expected[path.name] = summary(np.vstack([world_a, world_b]), scans=2, grid=None)


# ---------------------------------------------------------------------------------- LAS / LAZ


def write_las(bunny, expected):
    sel = bunny[::45]
    offset = np.array([-0.1, 0.03, -0.06])
    scale = np.array([1e-6, 1e-6, 1e-6])
    ints = np.round((sel - offset) / scale).astype(np.int64)
    stored = ints * scale + offset  # what a reader computes from the stored integers
    n = len(sel)
    for name, fmt, version, laz in [
        ("bunny.las", 3, "1.2", False),
        ("bunny.laz", 3, "1.2", True),
        ("bunny-14.las", 6, "1.4", False),
    ]:
        header = laspy.LasHeader(point_format=fmt, version=version)
        header.offsets = offset
        header.scales = scale
        las = laspy.LasData(header)
        las.X = ints[:, 0]
        las.Y = ints[:, 1]
        las.Z = ints[:, 2]
        las.intensity = (np.arange(n) * 37 % 65536).astype(np.uint16)
        las.gps_time = np.arange(n, dtype=np.float64) * 0.5
        if fmt == 3:
            las.red = np.full(n, 1000, dtype=np.uint16)
        path = OUT / name
        if laz:
            las.write(str(path), laz_backend=laspy.LazBackend.Lazrs)
        else:
            las.write(str(path))
        expected[name] = summary(stored, scans=1, grid=None)


# ----------------------------------------------------------------------------------------- PCD


def write_pcd(bunny, expected):
    sel = f32(bunny[::45])
    n = len(sel)
    x, y, z = (sel[:, k].astype(np.float32) for k in range(3))
    intensity = np.linspace(0, 1, n).astype(np.float32)
    rgb = PointCloud.encode_rgb(
        np.stack([np.arange(n) % 256, np.full(n, 40), np.full(n, 200)], axis=1).astype(np.uint8)
    )
    ring = (np.arange(n) % 16).astype(np.uint16)
    t = np.arange(n, dtype=np.float64) * 1e-3
    # Each file picks its fields, in its order, from these (values, stored type).
    columns = {
        "x": (x, np.float32),
        "y": (y, np.float32),
        "z": (z, np.float32),
        "rgb": (rgb, np.float32),
        "intensity": (intensity, np.float32),
        "ring": (ring, np.uint16),
        "t": (t, np.float64),
    }
    clouds = [
        ("bunny-ascii.pcd", Encoding.ASCII, ("x", "y", "z", "rgb")),
        ("bunny-binary.pcd", Encoding.BINARY, ("intensity", "x", "y", "z", "ring")),
        ("bunny-compressed.pcd", Encoding.BINARY_COMPRESSED, ("x", "y", "z", "intensity", "t")),
    ]
    for name, encoding, fields in clouds:
        pc = PointCloud.from_points(
            [columns[f][0] for f in fields], fields, tuple(columns[f][1] for f in fields)
        )
        pc.save(OUT / name, encoding=encoding)
        back = PointCloud.from_path(OUT / name).numpy(("x", "y", "z")).astype(np.float64)
        expected[name] = summary(back, grid=None)


# ----------------------------------------------------------------------------------------- PTX


def ptx_scan(verts, sub, matrix, colour):
    """One PTX scan as text lines, and the world points of its measured cells in file order.

    PTX lists the points column by column; the 4 x 4 matrix is written for row vectors,
    [x y z 1] M = world (rotation in the upper 3 x 3, translation in the last row).
    """
    rows, cols = sub.shape
    rot, tr = matrix[:3, :3], matrix[3, :3]
    lines = [str(cols), str(rows)]
    lines.append(" ".join(f"{v:.6f}" for v in tr))  # scanner position
    for k in range(3):
        lines.append(" ".join(f"{v:.6f}" for v in rot[k]))  # scanner axes
    for k in range(4):
        lines.append(" ".join(repr(float(v)) for v in matrix[k]))
    world, cells = [], []
    for c in range(cols):
        for r in range(rows):
            i = sub[r, c]
            extra = " 0 0 0" if colour else ""
            if i < 0:
                lines.append("0 0 0 0.5" + extra)
                continue
            p = verts[i]
            text = [f"{v:.7g}" for v in p]
            local = np.array([float(t) for t in text])
            world.append(np.append(local, 1.0) @ matrix)
            cells.append((c, r))
            extra = f" {c % 256} {r % 256} 99" if colour else ""
            lines.append(" ".join(text) + f" {0.25 + 0.5 * (i % 2)}" + extra)
    return lines, np.array(world)[:, :3], cells


def pose(axis, degrees, trans):
    m = np.eye(4)
    m[:3, :3] = quat_matrix(*unit_quat(axis, degrees)).T  # row-vector convention
    m[3, :3] = trans
    return m


def write_ptx(verts, grid, expected):
    m = pose([0.0, 0.0, 1.0], 30.0, [2.0, -1.0, 0.5])
    lines, world, cells = ptx_scan(verts, subgrid(grid, 10), m, colour=True)
    (OUT / "bun000-grid.ptx").write_text("\n".join(lines) + "\n")
    picks = [0, len(world) // 2, len(world) - 1]
    sub = subgrid(grid, 10)
    expected["bun000-grid.ptx"] = summary(
        world,
        scans=1,
        grid=[sub.shape[1], sub.shape[0]],
        cells=[[cells[k][0], cells[k][1], *world[k].tolist()] for k in picks],
    )
    m1 = pose([1.0, 1.0, 0.0], 45.0, [0.0, 0.0, 1.0])
    m2 = pose([0.0, 1.0, 0.0], -60.0, [-3.0, 0.25, 0.0])
    l1, w1, _ = ptx_scan(verts, subgrid(grid, 20), m1, colour=True)
    l2, w2, _ = ptx_scan(verts, subgrid(grid[5:, 3:], 20), m2, colour=False)
    (OUT / "two-scans.ptx").write_text("\n".join(l1 + l2) + "\n")
    expected["two-scans.ptx"] = summary(np.vstack([w1, w2]), scans=2, grid=None)


# ----------------------------------------------------------------------------------------- PTS


def write_pts(bunny, expected):
    sel = bunny[::90]
    lines = [str(len(sel))]
    back = []
    for k, p in enumerate(sel):
        text = [f"{v:.6f}" for v in p]
        back.append([float(t) for t in text])
        lines.append(" ".join(text) + f" {-2000 + k} {k % 256} 10 20")
    (OUT / "bunny.pts").write_text("\n".join(lines) + "\n")
    expected["bunny.pts"] = summary(np.array(back), grid=None)


# ---------------------------------------------------------------------------------------- glTF


def trs_matrix(t=(0, 0, 0), q=(0, 0, 0, 1), s=(1, 1, 1)):
    """glTF node TRS (quaternion x, y, z, w) as a 4 x 4 column-vector matrix T R S."""
    x, y, z, w = q
    m = np.eye(4)
    m[:3, :3] = quat_matrix(w, x, y, z) @ np.diag(s)
    m[:3, 3] = t
    return m


def apply(m, p):
    return p @ m[:3, :3].T + m[:3, 3]


def blob_builder():
    parts = []

    def add(array):
        offset = sum(len(p) for p in parts)
        data = array.tobytes()
        parts.append(data + b"\0" * (-len(data) % 4))
        return offset, len(data)

    return parts, add


def write_glb(suz_v, suz_f, expected):
    pos = suz_v.astype(np.float32)
    idx16 = suz_f.astype(np.uint16)
    strip = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [2, 0, 0], [2, 1, 0]], np.float32)
    strip_idx = np.array([0, 1, 2, 3, 4, 5], np.uint16)
    fan = np.array([[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1], [-1, 1, 1]], np.float32)
    pts = np.array([[5, 5, 5], [6, 5, 5], [7, 5, 5]], np.float32)
    line = np.array([[0, -1, 0], [0, -2, 0]], np.float32)
    parts, add = blob_builder()
    views, accessors = [], []

    def accessor(array, target, ctype, kind):
        off, length = add(array)
        views.append(pygltflib.BufferView(buffer=0, byteOffset=off, byteLength=length, target=target))
        a = pygltflib.Accessor(
            bufferView=len(views) - 1, componentType=ctype, count=len(array), type=kind
        )
        if kind == "VEC3":
            a.min = array.min(axis=0).tolist()
            a.max = array.max(axis=0).tolist()
        accessors.append(a)
        return len(accessors) - 1

    F, U16 = pygltflib.FLOAT, pygltflib.UNSIGNED_SHORT
    AB, EAB = pygltflib.ARRAY_BUFFER, pygltflib.ELEMENT_ARRAY_BUFFER
    a_pos = accessor(pos, AB, F, "VEC3")
    a_idx = accessor(idx16.reshape(-1), EAB, U16, "SCALAR")
    a_strip = accessor(strip, AB, F, "VEC3")
    a_strip_idx = accessor(strip_idx, EAB, U16, "SCALAR")
    a_fan = accessor(fan, AB, F, "VEC3")
    a_pts = accessor(pts, AB, F, "VEC3")
    a_line = accessor(line, AB, F, "VEC3")
    prim = lambda a, mode, indices=None: pygltflib.Primitive(
        attributes=pygltflib.Attributes(POSITION=a), indices=indices, mode=mode
    )
    meshes = [
        pygltflib.Mesh(name="suzanne", primitives=[prim(a_pos, pygltflib.TRIANGLES, a_idx)]),
        pygltflib.Mesh(
            name="odds",
            primitives=[
                prim(a_strip, pygltflib.TRIANGLE_STRIP, a_strip_idx),
                prim(a_fan, pygltflib.TRIANGLE_FAN),
                prim(a_pts, pygltflib.POINTS),
                prim(a_line, pygltflib.LINES),
            ],
        ),
    ]
    root_t, root_q, root_s = [1.0, 2.0, 3.0], [0.0, 0.7071067811865476, 0.0, 0.7071067811865476], [2.0, 2.0, 2.0]
    child = trs_matrix(t=[0.5, 0.0, 0.0], q=[0.0, 0.0, 0.3826834323650898, 0.9238795325112867])
    nodes = [
        pygltflib.Node(name="root", translation=root_t, rotation=root_q, scale=root_s, children=[1, 2]),
        pygltflib.Node(name="suzanne", mesh=0, matrix=child.T.reshape(-1).tolist()),
        pygltflib.Node(name="odds", mesh=1),
        pygltflib.Node(name="suzanne again", mesh=0, translation=[-3.0, 0.0, 0.0]),
        pygltflib.Node(name="not in the scene", mesh=0, translation=[100.0, 0.0, 0.0]),
    ]
    blob = b"".join(parts)
    gltf = pygltflib.GLTF2(
        scene=0,
        scenes=[pygltflib.Scene(nodes=[0, 3])],
        nodes=nodes,
        meshes=meshes,
        accessors=accessors,
        bufferViews=views,
        buffers=[pygltflib.Buffer(byteLength=len(blob))],
    )
    gltf.set_binary_blob(blob)
    gltf.save_binary(str(OUT / "suzanne-scene.glb"))

    root = trs_matrix(root_t, root_q, root_s)
    world = np.vstack(
        [
            apply(root @ child, pos.astype(np.float64)),
            apply(root, strip.astype(np.float64)),
            apply(root, fan.astype(np.float64)),
            apply(root, pts.astype(np.float64)),
            apply(root, line.astype(np.float64)),
            apply(trs_matrix(t=[-3.0, 0.0, 0.0]), pos.astype(np.float64)),
        ]
    )
    triangles = 2 * len(suz_f) + (len(strip) - 2) + (len(fan) - 2)
    expected["suzanne-scene.glb"] = summary(world, triangles=triangles, grid=None)

    # Interleaved positions and normals, u32 indices, the buffer as a data: URI.
    normals = np.zeros_like(suz_v)
    for a, b, c in suz_f:
        n = np.cross(suz_v[b] - suz_v[a], suz_v[c] - suz_v[a])
        normals[[a, b, c]] += n
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    inter = np.hstack([pos, normals.astype(np.float32)]).astype(np.float32)
    idx32 = suz_f.astype(np.uint32).reshape(-1)
    parts, add = blob_builder()
    off_v, len_v = add(inter)
    off_i, len_i = add(idx32)
    blob = b"".join(parts)
    m = trs_matrix(t=[0.0, 0.0, -1.0], q=[0.25881904510252074, 0.0, 0.0, 0.9659258262890683], s=[0.5, 1.0, 1.5])
    gltf = pygltflib.GLTF2(
        scene=0,
        scenes=[pygltflib.Scene(nodes=[0])],
        nodes=[pygltflib.Node(mesh=0, matrix=m.T.reshape(-1).tolist())],
        meshes=[
            pygltflib.Mesh(
                primitives=[
                    pygltflib.Primitive(
                        attributes=pygltflib.Attributes(POSITION=0, NORMAL=1), indices=2
                    )
                ]
            )
        ],
        accessors=[
            pygltflib.Accessor(bufferView=0, byteOffset=0, componentType=F, count=len(pos), type="VEC3",
                               min=pos.min(axis=0).tolist(), max=pos.max(axis=0).tolist()),
            pygltflib.Accessor(bufferView=0, byteOffset=12, componentType=F, count=len(pos), type="VEC3"),
            pygltflib.Accessor(bufferView=1, componentType=pygltflib.UNSIGNED_INT, count=len(idx32), type="SCALAR"),
        ],
        bufferViews=[
            pygltflib.BufferView(buffer=0, byteOffset=off_v, byteLength=len_v, byteStride=24, target=AB),
            pygltflib.BufferView(buffer=0, byteOffset=off_i, byteLength=len_i, target=EAB),
        ],
        buffers=[pygltflib.Buffer(byteLength=len(blob))],
    )
    gltf.set_binary_blob(blob)
    gltf.convert_buffers(pygltflib.BufferFormat.DATAURI)
    gltf.save_json(str(OUT / "suzanne-embedded.gltf"))
    expected["suzanne-embedded.gltf"] = summary(
        apply(m, pos.astype(np.float64)), triangles=len(suz_f), grid=None
    )


def main():
    data = objfile.data_dir()
    OUT.mkdir(parents=True, exist_ok=True)
    verts, grid = read_bun000(data / "bun000.ply")
    bunny, _ = read_obj(data / "stanford-bunny.obj")
    suz_v, suz_f = read_obj(data / "corpus" / "suzanne.obj")
    expected = {}
    write_e57(verts, grid, bunny, expected)
    write_las(bunny, expected)
    write_pcd(bunny, expected)
    write_ptx(verts, grid, expected)
    write_pts(bunny, expected)
    write_glb(suz_v, suz_f, expected)
    (OUT / "expected.json").write_text(json.dumps(expected, indent=1, sort_keys=True) + "\n")
    for name in sorted(expected):
        print(f"{name}: {(OUT / name).stat().st_size} bytes, {expected[name]['points']} points")


if __name__ == "__main__":
    main()
