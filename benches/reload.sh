#!/usr/bin/env bash
# Time from saving a .brdf file to the changed pixel on screen: the window
# (default layout of nine views, 1280x800, under its own Xvfb) opens a file
# whose lit sphere is red, then the file is replaced by a green version (and
# back) by `rename`, as editors save, TRIALS times, GAP seconds apart; a
# one-pixel observer (benches/pixwait.c) reports when the lit sphere's centre
# turned. GAP of 30 s lets the environment view converge between saves (a
# window at rest); 4 s keeps it sampling.
#
#   bash benches/reload.sh [TRIALS] [GAP]
#
# Needs Xvfb, a C compiler and Xlib's headers (Debian: xvfb gcc libx11-dev).
# Build first: cargo build --release --bin bv
set -euo pipefail
trials=${1:-6}
gap=${2:-4}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bv=${CARGO_TARGET_DIR:-$root/target}/${BV_PROFILE:-release}/bv
[ -x "$bv" ] || { echo "missing $bv (cargo build --release --bin bv)" >&2; exit 2; }
work=$(mktemp -d)
trap 'kill $bp $xp 2>/dev/null || true; rm -rf "$work"' EXIT
cc -O2 -o "$work/pixwait" "$root/benches/pixwait.c" -lX11
brdf_file() {
    printf 'analytic\n::begin parameters\nfloat k 0 1 0.8\n::end parameters\n::begin shader\n'
    printf 'vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(%s); }\n::end shader\n' "$1"
}
brdf_file "k, 0.0, 0.0" > "$work/red.brdf"
brdf_file "0.0, k, 0.0" > "$work/green.brdf"
cp "$work/red.brdf" "$work/live.brdf"
display=:$((90 + RANDOM % 100))
Xvfb "$display" -screen 0 1400x900x24 >/dev/null 2>&1 & xp=$!
sleep 1
export DISPLAY=$display
mkdir -p -m 700 "$work/xdg"
XDG_RUNTIME_DIR=$work/xdg HOME=$work "$bv" --fresh --open "$work/live.brdf" \
    --size 1280x800 > "$work/bv.log" 2>&1 & bp=$!
# The lit sphere's centre in that layout (top right view).
x=1169 y=210
if ! "$work/pixwait" $x $y 0 "$(date +%s%3N)" 120000 > /dev/null; then
    echo "the window never showed the red lit sphere" >&2; cat "$work/bv.log" >&2; exit 1
fi
sleep "$gap"
for t in $(seq 1 "$trials"); do
    if [ $((t % 2)) = 1 ]; then src=green; ch=1; else src=red; ch=0; fi
    cp "$work/$src.brdf" "$work/live.tmp"
    t0=$(date +%s%3N)
    mv "$work/live.tmp" "$work/live.brdf"
    echo "save $t ($src): $("$work/pixwait" $x $y $ch "$t0" 10000) ms"
    sleep "$gap"
done
