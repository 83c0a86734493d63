#!/usr/bin/env bash
# Builds the demo (installing what the build needs) and serves it on 127.0.0.1; prints the URL.
# The port comes from PORT (default 8080).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build-wasm.sh
exec node scripts/serve.mjs
