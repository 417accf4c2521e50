# shellcheck shell=bash
# Sourced (not run) by run.sh and .ci/run: installs what a fresh Debian machine
# lacks to build, run and test bv. Everything is checked first, so a machine
# that has it all installs nothing and needs no network.

# Run time: the Vulkan loader and Mesa's drivers (lavapipe gives Vulkan on the
# CPU when there is no GPU), and the X11 libraries winit loads when it opens a
# window (it exits at start-up without libXcursor). No -dev packages are needed.
BV_RUN_PACKAGES=(libvulkan1 mesa-vulkan-drivers libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0)
# Tests: also a virtual X server and screenshots (ImageMagick's `import`),
# and Python with venv for the Python module's tests (.ci/python.sh).
BV_CI_PACKAGES=("${BV_RUN_PACKAGES[@]}" xvfb xauth imagemagick python3 python3-venv)
# The web build's test: a headless browser and Node.js for its driver
# (playwright-core, from npm, pinned in web/package-lock.json).
BV_WEB_PACKAGES=(chromium nodejs npm)

bv_log() { printf '==> %s\n' "$*" >&2; }
bv_warn() { printf 'warning: %s\n' "$*" >&2; }

# Prints those of the given Debian packages that are not installed.
bv_missing_packages() {
    local p
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || echo "$p"
    done
}

# Installs the given Debian packages that are missing (as root, or via sudo).
bv_apt_install() {
    local wanted=("$@")
    # Rust needs a C linker (`cc`); rustup does not bring one.
    command -v cc >/dev/null 2>&1 || wanted+=(gcc libc6-dev)
    if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
        bv_warn "not a Debian system: make sure these are installed: ${wanted[*]}"
        return 0
    fi
    local missing
    mapfile -t missing < <(bv_missing_packages "${wanted[@]}")
    [ "${#missing[@]}" -eq 0 ] && return 0
    local sudo=()
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1; then
            sudo=(sudo)
        else
            bv_warn "not root and no sudo: cannot install ${missing[*]}; continuing without them"
            return 0
        fi
    fi
    bv_log "apt-get install ${missing[*]}"
    "${sudo[@]}" apt-get update -qq
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# Makes `cargo` available: from ~/.cargo if it is there but not on PATH,
# otherwise installed with rustup (stable, minimal profile). Extra arguments are
# rustup components to add when missing (rustfmt, clippy).
bv_ensure_rust() {
    if ! command -v cargo >/dev/null 2>&1 && [ -f "$HOME/.cargo/env" ]; then
        # shellcheck disable=SC1091
        . "$HOME/.cargo/env"
    fi
    if ! command -v cargo >/dev/null 2>&1; then
        bv_log "installing the Rust toolchain with rustup (https://rustup.rs)"
        bv_apt_install curl ca-certificates
        curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs |
            sh -s -- -y --profile minimal --default-toolchain stable
        # shellcheck disable=SC1091
        . "$HOME/.cargo/env"
    fi
    local c
    for c in "$@"; do
        if ! cargo "${c/rustfmt/fmt}" --version >/dev/null 2>&1; then
            if command -v rustup >/dev/null 2>&1; then
                bv_log "rustup component add $c"
                rustup component add "$c"
            else
                bv_warn "cargo ${c/rustfmt/fmt} is missing and there is no rustup to add it"
            fi
        fi
    done
}
