#!/usr/bin/env bash
# Benchmark of `geofit fit` on the Stanford bunny (SPEC §1, Table 1 model C): every weighting /
# acceleration choice for Loop, then Catmull–Clark and Doo–Sabin. Prints a Markdown table (one thread, release):
# wall times as the report gives them, and user CPU seconds of the process. The headline run (Loop, basis
# weights, CG) is repeated 3 times; its row gives the fastest and the median total, since other processes
# on the machine make single timings noisy.
# Usage: bash scripts/bench_fit.sh [DATA_DIR]   (default: ../shared/data, else /work/shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/data_dir.sh "${1:-}"
bunny="$data/stanford-bunny.obj"
cargo build --release --quiet
out=$(mktemp -d)
common=(--initial 612 --tol-avg 0.01 --tol-max 0.05 --max-control 7049 --max-iter 60 --threads 1 -q)
run() {
  local name="$1"; shift
  /usr/bin/time -f '%U' -o "$out/$name.cpu" \
    ./target/release/geofit fit "$bunny" "${common[@]}" --json "$out/$name.json" "$@" >/dev/null || true
}
for k in 1 2 3; do
  run "loop-basis-cg.$k" --scheme loop --weights basis --accel cg
done
run loop-basis-anderson --scheme loop --weights basis --accel anderson
run loop-basis-none --scheme loop --weights basis --accel none
run loop-patent-none --scheme loop --weights patent --accel none
run cc-basis-cg --scheme catmull-clark --weights basis --accel cg
# Catmull–Clark starts from 3,593 points (one CC step of the 612-vertex mesh) and does not reach
# E_max 0.05 % within 7,049 points; this row gives it the budget it needs.
common=(--initial 612 --tol-avg 0.01 --tol-max 0.05 --max-control 10000 --max-iter 120 --threads 1 -q)
run cc-basis-cg-10000 --scheme catmull-clark --weights basis --accel cg
common=(--initial 612 --tol-avg 0.01 --tol-max 0.05 --max-control 7049 --max-iter 60 --threads 1 -q)
run ds-basis-cg --scheme doo-sabin --weights basis --accel cg
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1 /proc/loadavg)"
echo
python3 - "$out" <<'PY'
import glob, json, os, statistics, sys
runs = {}
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    name = os.path.basename(path)[:-5].split(".")[0]
    report = json.load(open(path))
    cpu_path = path[:-5] + ".cpu"
    cpu = float(open(cpu_path).read().split()[-1]) if os.path.exists(cpu_path) else float("nan")
    runs.setdefault(name, []).append((report, cpu))
print("| run | converged | iterations | control points | E_avg % | E_max % | E_rms % | precompute s | fit s | total s | CPU s |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for name, rs in runs.items():
    rs.sort(key=lambda x: x[0]["total_s"])
    r, cpu = rs[0]
    total = f"{r['total_s']:.2f}"
    cpus = f"{cpu:.2f}"
    if len(rs) > 1:
        total += f" (median {statistics.median(x[0]['total_s'] for x in rs):.2f} of {len(rs)})"
        cpus += f" (median {statistics.median(x[1] for x in rs):.2f})"
    print(f"| {name} | {r['converged']} | {r['iterations']} | {r['initial_control_points']} → {r['final_control_points']} | "
          f"{r['e_avg_pct']:.4f} | {r['e_max_pct']:.4f} | {r['e_rms_pct']:.4f} | {r['precompute_s']:.2f} | {r['fit_s']:.2f} | {total} | {cpus} |")
# Where the time goes: per phase of the fastest headline run, summed over its iterations and as a
# mean per iteration with and without a refinement ("other" is the rest of each iteration).
name = "loop-basis-cg"
if name in runs:
    r = runs[name][0][0]
    phases = ["moves_ms", "refill_ms", "feet_ms", "back_ms", "refine_ms"]
    print()
    print(f"Phases of {name} (fastest run), ms:")
    print()
    print("| iterations | count | moves | refill | foot points | surface → data | refinement | other | total |")
    print("|---|---|---|---|---|---|---|---|---|")
    def row(label, hs, mean):
        if not hs:
            return
        div = len(hs) if mean else 1
        sums = [sum(h.get("phases", {}).get(p, 0.0) for h in hs) / div for p in phases]
        total = sum(h["ms"] for h in hs) / div
        cells = " | ".join(f"{v:.1f}" for v in sums + [total - sum(sums), total])
        print(f"| {label} | {len(hs)} | {cells} |")
    history = r["history"]
    row("all (sum)", history, False)
    row("without refinement (mean)", [h for h in history if not h["refined"]], True)
    row("with refinement (mean)", [h for h in history if h["refined"]], True)
PY
rm -rf "$out"
