#!/usr/bin/env bash
# The Python module's tests (issue 30), run by .ci/run after the cargo tests:
#   bash .ci/python.sh
# Makes a virtual environment (.venv-ci, kept between runs; python3 -m venv:
# Debian's python3-venv), installs numpy, maturin and pytest into it, builds
# the module with `maturin develop` in the dev profile into the workspace's
# target directory (the bv and bv-core the cargo tests just built are reused,
# only the module itself is compiled), and runs pytest against the `bv`
# binary of the same build. BV_CI_PYTHON=0 in .ci/run skips it.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
target=${CARGO_TARGET_DIR:-$root/target}
export CARGO_TARGET_DIR=$target
venv=${BV_PY_VENV:-$root/.venv-ci}

if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
# Pinned below the next major versions; pip skips what is already there.
"$venv/bin/python" -m pip install -q --disable-pip-version-check \
    'numpy>=1.21,<3' 'maturin>=1.5,<2' 'pytest>=7,<10'
# The `bv` binary the tests compare with (built by `cargo test` already).
cargo build -q --bin bv
# VIRTUAL_ENV tells maturin where to install.
VIRTUAL_ENV=$venv PATH="$venv/bin:$PATH" \
    "$venv/bin/maturin" develop -q --manifest-path python/Cargo.toml
BV_BIN="$target/debug/bv" "$venv/bin/python" -m pytest -q python/tests
