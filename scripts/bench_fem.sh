#!/usr/bin/env bash
# FEM quad-mesh benchmark: meshes the fitted bun000 B-spline surface and the spot Catmull–Clark
# surface at 10K, 100K, 390K (the paper's figure) and 1M elements, best of 5, and times the MSH
# writer. A benchmark, not a test: run it on a quiet machine.
#
#   bash scripts/bench_fem.sh [DATA_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/data_dir.sh "${1:-}"
cargo run --release --quiet --example bench_fem -- "$data"
