#!/usr/bin/env bash
# The f32 batch kernels on the instruction sets this machine does not run
# natively: bv-core's batch parity test (crates/bv-core/tests/batch_parity.rs,
# every kernel of the catalogue and the lane math against the f64 reference)
#  - cross-compiled for aarch64-unknown-linux-gnu (the NEON path) and run
#    under qemu-user, and
#  - compiled for wasm32-wasip1 with WebAssembly SIMD (the simd128 path the
#    browser build uses) and run under Node.js's WASI (.ci/wasi-run.mjs).
# Installs what a fresh Debian machine lacks: qemu-user (for qemu-aarch64),
# the cross linker gcc-aarch64-linux-gnu and the Arm C library
# libc6-dev-arm64-cross, Node.js (apt-get, as root or via sudo), and the Rust
# targets (rustup target add). Linkers, runners and flags are set here through
# Cargo's environment variables, not a config file, so native builds are
# untouched.
#
#   bash .ci/simd.sh
#
# Takes under a minute to install, then about 6 minutes from cold on 2 cores
# to build both (debug profile) and under a minute to test.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
# shellcheck source=.ci/deps.sh
. .ci/deps.sh

target=aarch64-unknown-linux-gnu
wasi=wasm32-wasip1
packages=(qemu-user gcc-aarch64-linux-gnu libc6-dev-arm64-cross)
command -v node >/dev/null 2>&1 || packages+=(nodejs)
bv_apt_install "${packages[@]}"
bv_ensure_rust
for t in "$target" "$wasi"; do
    if [ ! -d "$(rustc --print sysroot)/lib/rustlib/$t" ]; then
        if ! command -v rustup >/dev/null 2>&1; then
            bv_warn "the Rust standard library for $t is missing and there is no rustup to add it"
            exit 1
        fi
        bv_log "rustup target add $t"
        rustup target add "$t"
    fi
done

# Debian's qemu-user has qemu-aarch64 (older and newer releases may only have
# qemu-user-static's qemu-aarch64-static). -L: the Arm dynamic loader and libc.
qemu=$(command -v qemu-aarch64 || command -v qemu-aarch64-static || true)
if [ -z "$qemu" ]; then
    bv_warn "no qemu-aarch64: install Debian's qemu-user"
    exit 1
fi
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="$qemu -L /usr/aarch64-linux-gnu"
# WebAssembly has no run-time detection: SIMD is a compile-time choice, as in
# the browser build (.cargo/config.toml).
export CARGO_TARGET_WASM32_WASIP1_RUSTFLAGS="-C target-feature=+simd128"
export CARGO_TARGET_WASM32_WASIP1_RUNNER="node $root/.ci/wasi-run.mjs"

log=$(mktemp)
trap 'rm -f "$log"' EXIT
# Both run even when the first fails; --show-output prints the passed tests'
# output too (the kernels checked and the instruction sets they ran on).
failed=()
run() {
    local t=$1
    shift
    bv_log "cargo test -p bv-core --target $t $*"
    cargo test -p bv-core --target "$t" "$@" -- --show-output 2>&1 | tee -a "$log" ||
        failed+=("$t $*")
}
run "$target" --test batch_parity
run "$wasi" --test batch_parity

# What the tests printed (libtest's "---- NAME stdout ----" sections) that
# names an ISA.
isa=$(awk '/^---- .* ----$/ { out = 1; next }
    /^(successes|failures):$/ { out = 0 }
    out && /kernels checked on/' "$log" | sed 's/:.*//' | sort -u)
if [ -n "$isa" ]; then
    bv_log "$isa"
else
    bv_log "the tests did not say which ISA the kernels took"
fi
# A run that passed on the scalar path alone would test nothing it names.
for want in neon simd128; do
    if ! grep -q "kernels checked on $want" "$log"; then
        bv_warn "no kernel ran on $want"
        failed+=("the $want path")
    fi
done
if [ "${#failed[@]}" -ne 0 ]; then
    bv_warn "failed: ${failed[*]}"
    exit 1
fi
