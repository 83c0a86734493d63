#!/usr/bin/env bash
# QEM simplification, geofit against meshoptimizer and fast-simplification in one run: the
# Stanford bunny, the bunny Loop-subdivided three times (4.4 M triangles, built on the first
# run into bench-results/) and the corpus. See scripts/bench_qem.py for what is measured.
# Usage: bash scripts/bench_qem.sh [DATA_DIR] [-- options of bench_qem.py]
#        GEOFIT_BIN=path/to/geofit bash scripts/bench_qem.sh   (time a given binary, no build)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/data_dir.sh "${1:-}"
shift $(( $# > 0 ? 1 : 0 ))
[ "${1:-}" = "--" ] && shift
bin="${GEOFIT_BIN:-}"
if [ -z "$bin" ]; then
  cargo build --release --quiet --bin geofit
  bin="${CARGO_TARGET_DIR:-target}/release/geofit"
fi
if ! .venv/bin/python -c "import meshoptimizer, fast_simplification, numpy" 2>/dev/null; then
  python3 -m venv .venv
  .venv/bin/pip install --quiet $(grep -E '^(numpy|meshoptimizer|fast-simplification)' scripts/bench-requirements.txt)
fi
exec .venv/bin/python scripts/bench_qem.py --geofit "$bin" --data "$data" "$@"
