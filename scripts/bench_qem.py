#!/usr/bin/env python3
"""QEM simplification: geofit against meshoptimizer and fast-simplification, in one run.

Each mesh is simplified by each tool to the same size — geofit to `--target` vertices (default:
612 for the bunnies, as in the patent's Table 1 model C, and 200 for the corpus), the peers to
the triangle count geofit's result has — and every result is measured the same way, by
`geofit simplify INPUT --measure RESULT`: the distance of every input vertex to the result
(max and rms, in % of the input's bounding-box diagonal) and its fold-overs. Times are the CPU
seconds of the simplification call alone, on one thread (geofit: `simplify_cpu_s`, the
thread's own CPU time, which includes its repair check; the peers: `time.process_time()`
around their call), and throughput is input triangles per CPU second. geofit's peak resident
memory (the whole `geofit simplify` process: reading, simplifying, measuring) is given per
input triangle. The machine and its load average are printed, as the machine is shared.

    bash scripts/bench_qem.sh                    (builds, sets up .venv, runs this)
    .venv/bin/python scripts/bench_qem.py --geofit target/release/geofit --data ../shared/data
        [--meshes bunny,bunny-l3,corpus] [--json out.json]
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
import meshoptimizer
import fast_simplification


def load_obj(path):
    """Vertices (float64) and fan-triangulated faces (uint32) of an OBJ file."""
    verts, faces = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                verts.append(line[2:])
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
                faces.extend((idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1))
    v = np.array(" ".join(verts).split(), dtype=np.float64).reshape(-1, 3)
    return v, np.array(faces, dtype=np.uint32).reshape(-1, 3)


def save_obj(path, v, f):
    with open(path, "w") as fh:
        fh.write("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in v))
        fh.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f))


def geofit_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def run_geofit(geofit, path, target, out_path):
    """geofit's own report, with the peak RSS of the process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    rep = geofit_json([geofit, "simplify", path, "--target", str(target), "--json", "-o", out_path])
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    rep["peak_rss_kib"] = peak if peak > before else None
    return rep


def run_meshopt(v, f, triangles):
    idx = f.reshape(-1).astype(np.uint32)
    dest = np.zeros_like(idx)
    pos = v.astype(np.float32)
    t = time.process_time()
    n = meshoptimizer.simplify(dest, idx, pos, target_index_count=3 * triangles, target_error=1.0)
    cpu = time.process_time() - t
    used = np.unique(dest[:n])
    remap = np.zeros(len(v), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return v[used], remap[dest[:n]].reshape(-1, 3), cpu


def run_fast(v, f, triangles):
    t = time.process_time()
    vo, fo = fast_simplification.simplify(v, f.astype(np.int64), target_count=triangles)
    return vo, fo, time.process_time() - t


def measure(geofit, path, result):
    return geofit_json([geofit, "simplify", path, "--measure", result, "--json"])


def row(mesh, tool, tris_in, rep, cpu):
    fold = rep["foldovers"]["count"]
    return {
        "mesh": mesh, "tool": tool, "input_triangles": tris_in, "vertices": rep["vertices"],
        "triangles": rep["triangles"], "cpu_s": cpu, "mtri_per_s": tris_in / cpu / 1e6 if cpu else None,
        "deviation_max_pct": rep["deviation_max_pct"], "deviation_rms_pct": rep["deviation_rms_pct"],
        "foldovers": fold,
    }


def bench_mesh(args, name, path, target, tmp):
    rows = []
    g_out = os.path.join(tmp, "geofit.obj")
    g = run_geofit(args.geofit, path, target, g_out)
    r = row(name, "geofit", g["input_triangles"], g, g["simplify_cpu_s"])
    r["relaxations"] = len(g["relaxations"])
    if g.get("peak_rss_kib"):
        r["peak_rss_bytes_per_triangle"] = g["peak_rss_kib"] * 1024 / g["input_triangles"]
    rows.append(r)
    v, f = load_obj(path)
    for tool, fn in (("meshoptimizer", run_meshopt), ("fast-simplification", run_fast)):
        vo, fo, cpu = fn(v, f, g["triangles"])
        out = os.path.join(tmp, f"{tool}.obj")
        save_obj(out, vo, fo)
        rows.append(row(name, tool, len(f), measure(args.geofit, path, out), cpu))
    return rows


def subdivided_bunny(args):
    """The bunny after three Loop steps (4.4 M triangles), made once into bench-results/."""
    out = os.path.join("bench-results", "bunny-loop3.obj")
    if not os.path.exists(out):
        os.makedirs("bench-results", exist_ok=True)
        subprocess.run([args.geofit, "subdiv", os.path.join(args.data, "stanford-bunny.obj"),
                        "--scheme", "loop", "--levels", "3", "-o", out], check=True,
                       stdout=subprocess.DEVNULL)
    return out


def meshes(args):
    chosen = args.meshes.split(",")
    if "bunny" in chosen:
        yield "stanford-bunny", os.path.join(args.data, "stanford-bunny.obj"), 612
    if "bunny-l3" in chosen:
        yield "bunny-loop3", subdivided_bunny(args), 612
    if "corpus" in chosen:
        corpus = os.path.join(args.data, "corpus")
        for name in sorted(os.listdir(corpus)):
            if name.endswith(".obj"):
                yield name[:-4], os.path.join(corpus, name), 200


def machine():
    model = "?"
    with open("/proc/cpuinfo") as fh:
        for line in fh:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{os.cpu_count()} cores, {model}"


def load():
    with open("/proc/loadavg") as fh:
        return " ".join(fh.read().split()[:3])


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--geofit", default="target/release/geofit")
    p.add_argument("--data", default="../shared/data")
    p.add_argument("--meshes", default="bunny,bunny-l3,corpus")
    p.add_argument("--json")
    args = p.parse_args()
    print(f"machine: {machine()}; load average {load()} at the start")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, path, target in meshes(args):
            rows.extend(bench_mesh(args, name, path, target, tmp))
            print_rows(rows[-3:])
            sys.stdout.flush()
    print(f"load average {load()} at the end")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


def print_rows(rows):
    for r in rows:
        extra = ""
        if "peak_rss_bytes_per_triangle" in r:
            extra += f"  peak RSS {r['peak_rss_bytes_per_triangle']:.0f} B/tri"
        if r.get("relaxations"):
            extra += f"  relaxed x{r['relaxations']}"
        num = lambda x, spec: "n/a" if x is None else format(x, spec)
        print(f"{r['mesh']:16s} {r['tool']:20s} {r['input_triangles']:>9,d} tri -> {r['vertices']:>5d} v "
              f"{num(r['cpu_s'], '8.3f')} s {num(r['mtri_per_s'], '6.2f')} M tri/s"
              f"  max {num(r['deviation_max_pct'], '.3f')} %  rms {num(r['deviation_rms_pct'], '.3f')} %"
              f"  fold-overs {r['foldovers']}{extra}")


if __name__ == "__main__":
    main()
