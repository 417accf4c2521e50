#!/usr/bin/env bash
# The Python module's tests (issue 30), run by .ci/run after the cargo tests:
#   bash .ci/python.sh
# Makes a virtual environment (.venv-ci, kept between runs; python3 -m venv:
# Debian's python3-venv), installs numpy, maturin, pytest and the example
# tests' tools (nbclient, ipykernel, dask.distributed) into it, builds the
# module with `maturin develop` in the dev profile into the workspace's
# target directory (the bv and bv-core the cargo tests just built are reused,
# only pyo3, numpy and the module itself are compiled), and runs pytest
# against the `bv` binary of the same build: the module's tests, the example
# notebook (nbclient) and the Dask study (a 2-worker LocalCluster).
# BV_CI_PYTHON=0 in .ci/run skips it.
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
# nbclient, nbformat and ipykernel run the example notebook headless
# (python/tests/test_notebook.py); dask[distributed] runs the batch study
# (python/tests/test_dask_study.py). They are for CI only: the module needs
# numpy alone.
"$venv/bin/python" -m pip install -q --disable-pip-version-check \
    'numpy>=1.21,<3' 'maturin>=1.5,<2' 'pytest>=7,<10' \
    'nbclient>=0.7,<1' 'nbformat>=5,<6' 'ipykernel>=6,<8' 'dask[distributed]>=2023.1'
# The `bv` binary the tests compare with, resolved over the whole workspace
# (`--workspace`) as `cargo test --workspace` resolves it, so that after
# .ci/run's `cargo test` it is fresh. A plain `cargo build --bin bv` resolves
# features for the `bv` package alone: pyo3's macros enable syn's
# `extra-traits`/`visit-mut` only in the workspace-wide resolution, so every
# crate behind serde_derive, thiserror, clap_derive or bytemuck_derive (61
# units, wgpu, naga, egui and bv itself among them) got a second build with
# different features: most of this script's 359 s on a clean clone.
cargo build -q --workspace --bin bv
# VIRTUAL_ENV tells maturin where to install. `maturin develop` builds
# `-p bv-python`, whose feature resolution is the workspace's (bv-python
# depends on bv), so bv, bv-core and their dependencies are reused; only
# pyo3, numpy and the module compile (maturin sets PYO3_CONFIG_FILE, which
# pyo3-ffi's build script watches, so they are rebuilt after a plain cargo
# build or clippy has built them without it).
VIRTUAL_ENV=$venv PATH="$venv/bin:$PATH" \
    "$venv/bin/maturin" develop -q --manifest-path python/Cargo.toml
# BV_CI=1: a missing optional dependency (nbclient, dask) fails its test
# instead of skipping it. The notebook's figures and bv.render draw offscreen
# (lavapipe), which wants a private runtime directory.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
    XDG_RUNTIME_DIR=$(mktemp -d)
    chmod 700 "$XDG_RUNTIME_DIR"
    export XDG_RUNTIME_DIR
    trap 'rm -rf "$XDG_RUNTIME_DIR"' EXIT
fi
BV_CI=1 BV_BIN="$target/debug/bv" "$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
