#!/usr/bin/env bash
# Builds (once) a Debian trixie root holding Monado 25, hello_xr 1.1.47, lavapipe and the
# core_validation and Vulkan validation layers, in a cache folder outside the clone, and prints its path.
# Exit codes: 0 ready, 77 debootstrap or the Debian mirror is unavailable, 1 other failure.
set -euo pipefail

cache=${STEADYXR_CACHE_DIR:-$HOME/.cache/steadyxr}
root=$cache/trixie-root
stamp=$root/.steadyxr-ready
packages=(monado-service libopenxr1-monado libopenxr-utils libopenxr-loader1 mesa-vulkan-drivers
  vulkan-tools xvfb openxr-layer-apidump openxr-layer-corevalidation libhidapi-hidraw0
  vulkan-validationlayers)

mkdir -p "$cache"
# One builder at a time; others wait for it and then reuse its result.
exec 9>"$cache/trixie-root.lock"
flock 9

if [[ -f $stamp ]]; then
  # A root cached by an older version of this script may lack a package added since.
  missing=()
  for p in "${packages[@]}"; do
    chroot "$root" dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ((${#missing[@]} > 0)); then
    echo "ensure_root: adding ${missing[*]} to the cached root" >&2
    if ! chroot "$root" /usr/bin/env DEBIAN_FRONTEND=noninteractive bash -c \
      "apt-get update -q && apt-get install -y -q --no-install-recommends ${missing[*]}" \
      >"$cache/chroot-apt.log" 2>&1; then
      tail -n 20 "$cache/chroot-apt.log" >&2
      exit 1
    fi
  fi
  echo "$root"
  exit 0
fi

if ! command -v debootstrap >/dev/null; then
  echo "ensure_root: debootstrap is not installed" >&2
  exit 77
fi
if [[ $(id -u) -ne 0 ]]; then
  echo "ensure_root: building the trixie root needs root (debootstrap, chroot)" >&2
  exit 77
fi

# The mirror apt already uses (deb822 or one-line sources), else deb.debian.org.
mirror=$(grep -hoE '^URIs: *http[^ ]*' /etc/apt/sources.list.d/*.sources 2>/dev/null | grep -v security |
  head -n1 | sed 's/^URIs: *//' || true)
if [[ -z $mirror ]]; then
  mirror=$(grep -hoE '^deb +http[^ ]+' /etc/apt/sources.list 2>/dev/null | grep -v security | head -n1 |
    awk '{print $2}' || true)
fi
mirror=${mirror:-http://deb.debian.org/debian}

work=$cache/trixie-root.partial
rm -rf "$work"
echo "ensure_root: debootstrap trixie from $mirror into $work (once; about 2 minutes)" >&2
if ! debootstrap --variant=minbase trixie "$work" "$mirror" >"$cache/debootstrap.log" 2>&1; then
  tail -n 20 "$cache/debootstrap.log" >&2
  if grep -qiE 'Failed getting release file|Could not resolve|Temporary failure|Connection (refused|timed out)|unable to fetch|Network is unreachable' "$cache/debootstrap.log"; then
    echo "ensure_root: the Debian mirror is unreachable" >&2
    rm -rf "$work"
    exit 77
  fi
  exit 1
fi
cp /etc/resolv.conf "$work/etc/resolv.conf"
if ! chroot "$work" /usr/bin/env DEBIAN_FRONTEND=noninteractive bash -c \
  "apt-get update -q && apt-get install -y -q --no-install-recommends ${packages[*]}" \
  >"$cache/chroot-apt.log" 2>&1; then
  tail -n 20 "$cache/chroot-apt.log" >&2
  exit 1
fi
chroot "$work" apt-get clean >/dev/null 2>&1 || true
touch "$work/.steadyxr-ready"
rm -rf "$root"
mv "$work" "$root"
echo "$root"
