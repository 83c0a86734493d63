#!/usr/bin/env bash
# Builds the browser package: the geofit crate for wasm32, then wasm-bindgen (ES module + TypeScript
# declarations) into pkg/, then wasm-opt -Oz, then scripts/package.mjs makes pkg/ the npm package
# `geofit` (package.json, the worker entry, README). Prints the .wasm size, raw and gzipped.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install.sh

# The wasm profile (Cargo.toml) trades build time for a smaller, faster .wasm.
cargo build --profile wasm-release --target wasm32-unknown-unknown --lib
wasm-bindgen --target web --out-dir pkg \
    "${CARGO_TARGET_DIR:-target}/wasm32-unknown-unknown/wasm-release/geofit.wasm"

# The features Rust's wasm32 target emits by default; wasm-opt must accept them, and may use no others.
node_modules/.bin/wasm-opt -Oz \
    --enable-bulk-memory --enable-bulk-memory-opt --enable-multivalue --enable-mutable-globals \
    --enable-nontrapping-float-to-int --enable-reference-types --enable-sign-ext \
    pkg/geofit_bg.wasm -o pkg/geofit_bg.wasm
node scripts/package.mjs

raw=$(stat -c %s pkg/geofit_bg.wasm)
gz=$(gzip -9 -c pkg/geofit_bg.wasm | wc -c)
echo "pkg/geofit_bg.wasm: $raw bytes raw, $gz bytes gzip -9"
