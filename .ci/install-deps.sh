#!/usr/bin/env bash
# Installs the Debian bookworm packages steadyxr builds, tests and evaluates with.
# Idempotent: does nothing when everything is already installed.
set -euo pipefail
packages=(
  build-essential cmake pkg-config git ca-certificates
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools glslang-tools spirv-tools
  libopenxr-dev libopenxr-loader1 libopenxr-utils openxr-layer-corevalidation openxr-layer-apidump
  libglm-dev libhidapi-dev libgtest-dev libgmock-dev libstb-dev
  python3 python3-matplotlib python3-numpy python3-pil python3-skimage
  debootstrap
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "steadyxr: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
