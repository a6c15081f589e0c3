#!/usr/bin/env bash
# Makes sure a Vulkan driver is present (Mesa's lavapipe on machines without a GPU), Xvfb
# with xvfb-run and xauth (the viewer's smoke test opens its window on a virtual display),
# Debian's Chromium (the report's and the web page's browser tests load it headless), Rust's
# wasm32 target and wasm-bindgen's CLI (`make web`).
# Installs them with apt when running as root or with password-less sudo; otherwise prints the
# exact command and fails.
set -euo pipefail

have_driver() {
    # a Vulkan loader plus at least one ICD manifest means a driver is installed
    local icd found=""
    for icd in /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json /usr/local/share/vulkan/icd.d/*.json; do
        [ -e "$icd" ] && found=1
    done
    [ -n "$found" ] || return 1
    local libs
    libs="$(ldconfig -p 2>/dev/null || true)"
    case "$libs" in
        *libvulkan.so.1*) return 0 ;;
        *) return 1 ;;
    esac
}

if ! command -v cargo >/dev/null 2>&1; then
    echo "error: cargo not found; install a stable Rust toolchain (rustup) and run make again" >&2
    exit 1
fi

have_xvfb() {
    command -v xvfb-run >/dev/null 2>&1 && command -v Xvfb >/dev/null 2>&1 && command -v xauth >/dev/null 2>&1
}

have_chromium() {
    [ -x /usr/bin/chromium ]
}

# The browser build (issue 40): `make test` checks that shadowlab-core and shadowlab-gpu compile
# for wasm32, which needs the target's standard library (a rustup component).
if ! rustc --print sysroot >/dev/null 2>&1 || [ ! -d "$(rustc --print sysroot)/lib/rustlib/wasm32-unknown-unknown" ]; then
    if command -v rustup >/dev/null 2>&1; then
        echo "setup: adding the wasm32-unknown-unknown target (rustup) for the web build's check" >&2
        rustup target add wasm32-unknown-unknown >&2
    else
        echo "error: the wasm32-unknown-unknown standard library is missing and rustup is not available; install it with your toolchain's installer" >&2
        exit 1
    fi
fi

# `make web`: wasm-bindgen's CLI at the version Cargo.lock pins for the library (their versions
# must match). Not --locked: the CLI's own lock names crates some registry mirrors lack.
want_bindgen=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' "$(dirname "$0")/../Cargo.lock")
if [ "$(wasm-bindgen --version 2>/dev/null | cut -d' ' -f2)" != "$want_bindgen" ]; then
    echo "setup: installing wasm-bindgen-cli $want_bindgen (cargo install) for the web build" >&2
    cargo install --quiet wasm-bindgen-cli --version "$want_bindgen" >&2
fi

if have_driver && have_xvfb && have_chromium; then
    exit 0
fi

PKGS="mesa-vulkan-drivers libvulkan1 xvfb xauth chromium"
if ! command -v apt-get >/dev/null 2>&1; then
    echo "error: a Vulkan driver, Xvfb or Chromium is missing and apt-get is not available; install your platform's Vulkan driver and Xvfb (on Debian/Ubuntu: sudo apt-get install $PKGS)" >&2
    exit 1
fi
if [ "$(id -u)" -eq 0 ]; then
    SUDO=""
elif sudo -n true 2>/dev/null; then
    SUDO="sudo -n"
else
    echo "error: a Vulkan driver, Xvfb or Chromium is missing. Run: sudo apt-get install -y $PKGS" >&2
    exit 1
fi
echo "setup: installing $PKGS (software Vulkan for machines without a GPU; Xvfb for the viewer's smoke test; Chromium for the report's browser test)" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq $PKGS >/dev/null
have_driver || { echo "error: Vulkan driver still missing after installing $PKGS" >&2; exit 1; }
have_xvfb || { echo "error: xvfb-run still missing after installing $PKGS" >&2; exit 1; }
have_chromium || { echo "error: /usr/bin/chromium still missing after installing $PKGS" >&2; exit 1; }
