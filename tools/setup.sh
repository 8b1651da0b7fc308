#!/usr/bin/env bash
# Installs what Tessera needs on Debian/Ubuntu: the Vulkan loader, Mesa's lavapipe (a CPU Vulkan
# driver, for machines without a GPU), the validation layers, shaderc/glslang static libraries
# for the build-time shader compiler, Xvfb and xdotool for the window tests, a TrueType font for the
# text of `tessera bench --plot`, CMake and g++ for the C ABI's C/C++ tests (crates/capi), and Rust
# if missing.
# Safe to run twice: apt-get and rustup skip what is already there.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PKGS=(build-essential pkg-config curl ca-certificates libvulkan1 libvulkan-dev mesa-vulkan-drivers
      vulkan-validationlayers libshaderc-dev glslang-dev spirv-tools xvfb xauth libx11-dev libxkbcommon-x11-0
      fonts-dejavu-core xdotool cmake g++)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
if ! command -v cargo >/dev/null 2>&1 && [ ! -x "$HOME/.cargo/bin/cargo" ]; then
  curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal --component rustfmt,clippy
fi
# The workspace's rust-version (egui needs 1.95): update a rustup toolchain that is older.
export PATH="$HOME/.cargo/bin:$PATH"
need=1.95
have=$(rustc --version 2>/dev/null | awk '{print $2}')
if [ -n "$have" ] && [ "$(printf '%s\n%s\n' "$need" "$have" | sort -V | head -n1)" != "$need" ]; then
  if command -v rustup >/dev/null 2>&1; then
    rustup update stable --no-self-update && rustup default stable
  else
    echo "setup: Rust $have is older than $need and was not installed by rustup; install a newer Rust" >&2
    exit 1
  fi
fi
