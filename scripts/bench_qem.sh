#!/usr/bin/env bash
# Benchmark of the QEM simplification that builds a fit's initial control mesh: the Stanford bunny
# (35,947 vertices) to 612 vertices, as in `geofit fit --initial 612`, run RUNS times (default 7).
# Prints each run's `simplify_s` (wall seconds of the simplification alone, as `geofit simplify`
# reports it) and the user CPU seconds of the whole process (reading the OBJ and the deviation
# included), then the minimum and median, the deviation of the result and the load average.
# Usage: bash scripts/bench_qem.sh [DATA_DIR]   (default: ../shared/data, else /work/shared/data)
#        GEOFIT_BIN=path/to/geofit bash scripts/bench_qem.sh   (time a given binary, no build)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/data_dir.sh "${1:-}"
bin="${GEOFIT_BIN:-}"
if [ -z "$bin" ]; then
  cargo build --release --quiet --bin geofit
  bin=./target/release/geofit
fi
runs="${RUNS:-7}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for k in $(seq "$runs"); do
  /usr/bin/time -f '%U' -o "$out/$k.cpu" \
    "$bin" simplify "$data/stanford-bunny.obj" --target 612 --json >"$out/$k.json"
done
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out" "$runs" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
rep = [json.load(open(f"{out}/{k}.json")) for k in range(1, runs + 1)]
cpu = [float(open(f"{out}/{k}.cpu").read().split()[-1]) for k in range(1, runs + 1)]
s = [r["simplify_s"] for r in rep]
print("simplify_s:", " ".join(f"{x:.3f}" for x in s))
print("process user s:", " ".join(f"{x:.2f}" for x in cpu))
print(f"simplify_s min {min(s):.3f} median {statistics.median(s):.3f}; "
      f"process user s min {min(cpu):.2f} median {statistics.median(cpu):.2f}")
r = rep[0]
print(f"result: {r['vertices']} vertices, {r['triangles']} triangles; deviation of the input "
      f"vertices max {r['deviation_max_pct']:.4f} % rms {r['deviation_rms_pct']:.4f} % "
      f"mean {r['deviation_mean_pct']:.4f} % of the bounding-box diagonal")
PY
