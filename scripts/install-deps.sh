#!/usr/bin/env bash
# Installs the Debian 12 packages CrossRT needs. Does nothing when they are already there.
set -euo pipefail
PACKAGES=(
  cmake ninja-build g++ ccache pkg-config
  clang-19 libclang-19-dev llvm-19-dev libzstd-dev          # the translator (Clang LibTooling)
  glslang-tools glslang-dev spirv-tools                   # GLSL -> SPIR-V, spirv-val
  libvulkan-dev vulkan-tools vulkan-validationlayers       # loader, headers, validation layers
  mesa-vulkan-drivers                                      # lavapipe, the CPU Vulkan driver
  libembree-dev                                            # CPU ray tracing reference
  libassimp-dev zlib1g-dev                                 # mesh files (OFF, PLY, OBJ, gzipped)
  libtinygltf-dev                                          # glTF 2.0 scenes for the path tracer (its header)
  libopenimageio-dev openimageio-tools                     # image IO
  catch2 nlohmann-json3-dev libkainjow-mustache-dev libxxhash-dev
  python3-matplotlib                                       # plots of the benchmarks' CSV tables
  libhiredis-dev libcurl4-openssl-dev libssl-dev           # the remote translation cache (Redis, HTTP, HMAC)
  redis-server nginx-light openssl                         # its tests' servers, on loopback ports, and TLS keys
  libopenvdb-dev                                           # bench_sdf's peer: OpenVDB level sets
  neovim                                                   # the language server's test drives Neovim's LSP client
  libcli11-dev                                             # the programs' command lines (CLI11)
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
