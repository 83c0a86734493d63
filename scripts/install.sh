#!/usr/bin/env bash
# Installs what building (and, with --browser, testing) geofit's browser half needs on a Debian
# machine with rustup, Node 20/npm and root. Every step is skipped when its tool is already there,
# so a warm run takes a second or two.
#
#   bash scripts/install.sh            # wasm32 target, wasm-bindgen-cli, npm packages
#   bash scripts/install.sh --browser  # ... plus Debian chromium for the end-to-end tests
set -euo pipefail
cd "$(dirname "$0")/.."

log() { printf '[install] %s\n' "$*" >&2; }

# The wasm32 target of the rustup toolchain.
install_wasm_target() {
    if rustup target list --installed | grep -qx wasm32-unknown-unknown; then
        return
    fi
    log "adding rust target wasm32-unknown-unknown"
    rustup target add wasm32-unknown-unknown
}

# The wasm-bindgen version pinned in Cargo.lock: the CLI must match the crate exactly.
locked_wasm_bindgen_version() {
    awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock
}

# wasm-bindgen-cli at exactly that version (a cargo build from crates.io, ~4 min cold).
install_wasm_bindgen() {
    local want have
    want="$(locked_wasm_bindgen_version)"
    if [[ -z "$want" ]]; then
        log "error: no wasm-bindgen entry in Cargo.lock"
        exit 1
    fi
    have="$(wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)"
    if [[ "$have" == "$want" ]]; then
        return
    fi
    log "installing wasm-bindgen-cli $want (found '${have:-none}')"
    cargo install wasm-bindgen-cli --version "$want"
}

# npm packages from package-lock.json (binaryen's wasm-opt, playwright-core). Re-run npm ci only
# when the lock file changed since the last install.
install_npm_packages() {
    local stamp=node_modules/.package-lock.json
    if [[ -f "$stamp" && -x node_modules/.bin/wasm-opt && ! package-lock.json -nt "$stamp" ]]; then
        return
    fi
    log "installing npm packages (npm ci)"
    npm ci --no-audit --no-fund
}

# Debian's chromium, which the end-to-end tests drive (never a downloaded browser).
install_chromium() {
    if [[ -x /usr/bin/chromium ]]; then
        return
    fi
    log "installing Debian chromium"
    local sudo=""
    if [[ "$(id -u)" != 0 ]]; then
        sudo="sudo"
    fi
    $sudo apt-get update
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y chromium chromium-driver
}

main() {
    install_wasm_target
    install_wasm_bindgen
    install_npm_packages
    if [[ "${1:-}" == "--browser" ]]; then
        install_chromium
    fi
}

main "$@"
