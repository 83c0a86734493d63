#!/usr/bin/env bash
# Runs every test of geofit. Installs what it needs first; fast when it is already installed.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release
