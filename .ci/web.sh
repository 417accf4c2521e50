#!/usr/bin/env bash
# The browser build's check: installs what a fresh Debian machine lacks
# (chromium, Node.js and npm; the wasm32 target and wasm-bindgen-cli come
# with web/build.sh, the latter at opt-level 1 here), builds the bundle in
# the web-ci profile (the dev profile, lighter still: see Cargo.toml; the
# page is the same), installs the pinned test driver and runs the
# headless-browser test. Screenshots are left in web/shots for a human.
#
#   bash .ci/web.sh
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
# shellcheck source=.ci/deps.sh
. .ci/deps.sh

# Node.js and npm may come from elsewhere (NodeSource's nodejs carries its
# own npm and conflicts with Debian's npm package): only what is missing as a
# command is installed.
web_packages=(chromium)
command -v node >/dev/null 2>&1 || web_packages+=(nodejs)
command -v npm >/dev/null 2>&1 || web_packages+=(npm)
bv_apt_install "${web_packages[@]}"
bv_ensure_rust
BV_WEB_PROFILE=${BV_WEB_PROFILE:-web-ci} BV_BINDGEN_OPT_LEVEL=${BV_BINDGEN_OPT_LEVEL:-1} bash web/build.sh
npm ci --prefix web --no-audit --no-fund
# Chromium and Mesa want a private runtime directory (see .ci/run).
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
    XDG_RUNTIME_DIR=$(mktemp -d)
    chmod 700 "$XDG_RUNTIME_DIR"
    export XDG_RUNTIME_DIR
fi
# The desktop binary writes the RGL file the page test drops (`bv tabulate
# --format rgl`): .ci/run's cargo test has built it; alone, this builds it
# (as .ci/python.sh does, resolved with the workspace's features).
if [ -z "${BV_BIN:-}" ]; then
    BV_BIN="${CARGO_TARGET_DIR:-target}/debug/bv"
    [ -x "$BV_BIN" ] || cargo build -q --workspace --bin bv
fi
export BV_BIN
node web/test.mjs
