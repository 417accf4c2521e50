#!/usr/bin/env bash
# Builds and runs bv on a fresh Debian machine:
#   ./run.sh              opens the viewer
#   ./run.sh models       any arguments go to bv (see README.md)
# First installs what is missing: the run-time packages (apt-get, as root or via
# sudo) and, if there is no cargo, the Rust toolchain (rustup). The first build
# takes several minutes; later runs start at once.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=.ci/deps.sh
. "$root/.ci/deps.sh"

bv_apt_install "${BV_RUN_PACKAGES[@]}"
bv_ensure_rust

# Stay in the caller's directory, so that relative paths given to bv work.
exec cargo run --release --manifest-path "$root/Cargo.toml" --bin bv -- "$@"
