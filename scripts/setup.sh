#!/usr/bin/env bash
# What `cargo run --release -- run SCENARIO` needs on a fresh Debian or Ubuntu machine (run as
# root): a Vulkan driver, and the C linker Rust links with. Mesa's lavapipe (CPU Vulkan) serves
# machines without a GPU; a machine with a GPU and its vendor's driver already has one. A fresh
# Debian image has no `cc` (rustc's linker) and no `curl` (rustup's installer), so both are added
# where missing. The tests need more: scripts/setup-tests.sh.
set -euo pipefail
need_apt=()
[ -e /usr/share/vulkan/icd.d/lvp_icd.x86_64.json ] || [ -e /usr/share/vulkan/icd.d/lvp_icd.json ] || need_apt+=(mesa-vulkan-drivers)
ldconfig -p | grep -q 'libvulkan.so.1' || need_apt+=(libvulkan1)
command -v cc >/dev/null || need_apt+=(gcc libc6-dev)
command -v cargo >/dev/null || command -v curl >/dev/null || need_apt+=(curl ca-certificates)
if [ ${#need_apt[@]} -gt 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${need_apt[@]}" >/dev/null
fi
# Rust (the version Cargo.toml's rust-version names, or newer) comes from rustup, not apt.
if ! command -v cargo >/dev/null; then
    echo "setup.sh: the Vulkan driver and a C linker are installed; Rust is not. Install it with rustup:" >&2
    echo "  curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y && . ~/.cargo/env" >&2
    exit 1
fi
