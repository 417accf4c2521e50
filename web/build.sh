#!/usr/bin/env bash
# Builds bv's web bundle into web/dist: the `bv` binary for
# wasm32-unknown-unknown, its JavaScript glue from wasm-bindgen, and
# index.html. With --serve [PORT] it then serves the bundle on
# http://localhost:PORT/ (default 8080) until interrupted.
#
#   bash web/build.sh                 # release build (smaller, faster page)
#   BV_WEB_PROFILE=dev bash web/build.sh   # quicker to build
#   BV_WEB_PROFILE=web-ci bash web/build.sh   # quicker still (CI, Cargo.toml)
#   bash web/build.sh --serve 8080
#
# The bundler is wasm-bindgen-cli at exactly the version of the
# `wasm-bindgen` crate in Cargo.lock (the two must match); it is installed
# with `cargo install` when missing, optimised at BV_BINDGEN_OPT_LEVEL
# (default 3, release's; CI takes 1, quicker to build). (trunk would do the
# same and more, but building it from source costs several times as long on
# a small CI machine.)
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
profile=${BV_WEB_PROFILE:-release}
out=web/dist
serve=
port=8080
while [ $# -gt 0 ]; do
    case "$1" in
        --serve) serve=1; if [ $# -gt 1 ] && [[ $2 =~ ^[0-9]+$ ]]; then port=$2; shift; fi ;;
        *) echo "usage: $0 [--serve [PORT]]" >&2; exit 2 ;;
    esac
    shift
done

log() { printf '==> %s\n' "$*" >&2; }

if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
    log "rustup target add wasm32-unknown-unknown"
    rustup target add wasm32-unknown-unknown
fi
# The version of the wasm-bindgen crate the build links (the line after its name).
want=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/[^0-9.]/, "", $0); print; exit }' Cargo.lock)
have=$(wasm-bindgen --version 2>/dev/null | awk '{ print $2 }' || true)
if [ "$have" != "$want" ]; then
    log "cargo install wasm-bindgen-cli $want (found: ${have:-none})"
    CARGO_PROFILE_RELEASE_OPT_LEVEL=${BV_BINDGEN_OPT_LEVEL:-3} \
        cargo install wasm-bindgen-cli --version "$want"
fi

case "$profile" in
    dev) dir=debug ;;
    *) dir=$profile ;;
esac
target=${CARGO_TARGET_DIR:-target}
log "cargo build --target wasm32-unknown-unknown --profile $profile --bin bv"
cargo build --target wasm32-unknown-unknown --profile "$profile" --bin bv
rm -rf "$out"
mkdir -p "$out"
wasm-bindgen --target web --no-typescript --out-dir "$out" --out-name bv \
    "$target/wasm32-unknown-unknown/$dir/bv.wasm"
cp web/index.html "$out/"
log "bundle: $(du -sh "$out" | cut -f1) in $out ($(du -h "$out/bv_bg.wasm" | cut -f1) of WebAssembly)"

if [ -n "$serve" ]; then
    log "serving on http://localhost:$port/ (Ctrl-C stops)"
    exec python3 -m http.server --bind 127.0.0.1 --directory "$out" "$port"
fi
