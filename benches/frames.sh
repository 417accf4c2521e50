#!/usr/bin/env bash
# Frame times of the bv window against the minimal eframe window
# (examples/minimal_window.rs: same renderer, size, present mode), side by
# side under one X server, ROUNDS times interleaved:
#
#   bash benches/frames.sh [FRAMES] [WIDTHxHEIGHT] [ROUNDS]
#
# bv sweeps a slider of the selected BRDF (Lambert + Cook-Torrance, the
# default scene) with `--bench-frames`. Prints each run's report and, per
# round, bv's p50 and p95 as multiples of the baseline's p50. Needs xvfb-run
# (Debian's xvfb) when no DISPLAY is set. Build first:
#   cargo build --release --bin bv --example minimal_window
set -euo pipefail
frames=${1:-120}
size=${2:-1280x800}
rounds=${3:-3}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
profile=${BV_PROFILE:-release}
bv=$target/$profile/bv
base=$target/$profile/examples/minimal_window
for b in "$bv" "$base"; do
    [ -x "$b" ] || { echo "missing $b (cargo build --$profile --bin bv --example minimal_window)" >&2; exit 2; }
done
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
    XDG_RUNTIME_DIR=$(mktemp -d); chmod 700 "$XDG_RUNTIME_DIR"; export XDG_RUNTIME_DIR
fi
run() {
    if [ -n "${DISPLAY:-}" ]; then "$@"; else
        w=${size%x*}; h=${size#*x}
        xvfb-run -a -s "-screen 0 $((w + 120))x$((h + 120))x24" "$@"
    fi
}
p50() { sed -n 's/.*frame time p50 \([0-9.]*\) ms.*/\1/p' | head -1; }
p95() { sed -n 's/.*frame time p50 [0-9.]* ms, p95 \([0-9.]*\) ms.*/\1/p' | head -1; }
for r in $(seq "$rounds"); do
    b=$(run "$base" "$frames" "$size" 2>/dev/null | grep '^baseline:')
    v=$(run "$bv" --fresh --size "$size" --bench-frames "$frames" 2>&1 | grep '^bench:')
    echo "$b"
    echo "$v"
    awk -v b="$(echo "$b" | p50)" -v v50="$(echo "$v" | p50)" -v v95="$(echo "$v" | p95)" -v r="$r" \
        'BEGIN { printf "round %d: bv p50 = %.2f x baseline p50, bv p95 = %.2f x bv p50\n", r, v50 / b, v95 / v50 }'
done
