#!/usr/bin/env bash
# Runs every test of geofit: formatting, clippy (native and wasm32), the native tests (unit,
# integration, doc), the wasm build, the type check of the page's modules against the package's
# declarations, the browser tests (tests/e2e/*.mjs in Debian chromium, both
# WebGL2 and WebGPU; package.test.mjs lints, packs, installs and bundles the npm package) and the Python interop tests (tests/interop/*.py). Installs what it needs
# first; fast when it is already installed. Prints how long each step took.
set -euo pipefail
cd "$(dirname "$0")/.."

declare -a timings=()
step() {
    local name=$1 start end
    shift
    printf '\n=== %s\n' "$name"
    start=$(date +%s)
    "$@"
    end=$(date +%s)
    timings+=("$(printf '%5ss  %s' $((end - start)) "$name")")
}

run_e2e() {
    shopt -s nullglob
    local files=(tests/e2e/*.mjs)
    if ((${#files[@]} == 0)); then
        echo "no browser tests"
        return
    fi
    node --test --test-concurrency=1 "${files[@]}"
}

run_interop() {
    shopt -s nullglob
    local files=(tests/interop/test_*.py)
    if ((${#files[@]} == 0)); then
        echo "no interop tests"
        return
    fi
    cargo build --release --bins
    if [[ ! -x .venv/bin/python ]]; then
        python3 -m venv .venv
    fi
    if [[ -f tests/interop/requirements.txt ]]; then
        .venv/bin/pip install --quiet --disable-pip-version-check -r tests/interop/requirements.txt
    fi
    # Each interop script is a plain program: it prints "N passed, N failed" and exits non-zero on
    # a failure (pytest would collect no test functions from them and exit 5).
    local f
    for f in "${files[@]}"; do
        GEOFIT_BIN="$(realpath "${CARGO_TARGET_DIR:-target}")/release/geofit" .venv/bin/python "$f"
    done
}

# tests/io_glb.rs writes its GLBs here; the Khronos validator checks them after the native tests.
GEOFIT_GLB_DIR="$(realpath -m "${CARGO_TARGET_DIR:-target}")/glb-samples"
export GEOFIT_GLB_DIR

total_start=$(date +%s)
step "install" bash scripts/install.sh --browser
step "cargo fmt --check" cargo fmt --check
step "clippy native" cargo clippy --all-targets -- -D warnings
step "clippy wasm32" cargo clippy --target wasm32-unknown-unknown --lib -- -D warnings
step "cargo test --release" cargo test --release
step "glTF validator" node scripts/validate-glb.mjs "$GEOFIT_GLB_DIR"
step "wasm build" bash scripts/build-wasm.sh
step "typecheck www" node_modules/.bin/tsc -p tsconfig.json
step "browser tests" run_e2e
step "interop tests" run_interop

printf '\n=== timings\n'
printf '%s\n' "${timings[@]}"
printf '%5ss  total\n' $(($(date +%s) - total_start))
