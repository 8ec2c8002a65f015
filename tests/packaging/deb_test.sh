#!/usr/bin/env bash
# The Debian package as a user gets it: built by CPack from the build tree, installed with dpkg
# into a Debian trixie root (an overlay over the cached e2e root, so that root stays clean),
# then hello_xr runs on Monado with nothing but STEADYXR_ENABLE=1 set (the implicit layer),
# `steadyxr status` must list the running instance, the layer must filter frames, and after
# `dpkg --purge` nothing of the package may be left.
#
#   deb_test.sh BUILD_DIR OUT_DIR
#
# Exit: 0 pass, 1 fail, 77 skipped (no root, no overlayfs, no trixie root).
set -uo pipefail

build=$(readlink -f "${1:?build dir}")
out=${2:?output dir}
here=$(cd "$(dirname "$0")" && pwd)
seconds=${STEADYXR_DEB_SECONDS:-6}
rm -rf "$out"
mkdir -p "$out"
out=$(readlink -f "$out")

failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

if [[ $(id -u) -ne 0 ]]; then
  echo "SKIP: installing a package into a root needs root (chroot, mount)"
  exit 77
fi

# 1. Build the package (cpack installs the build tree's targets into a staging folder).
if ! (cd "$build" && cpack -G DEB -B "$out/cpack" >"$out/cpack.log" 2>&1); then
  tail -n 30 "$out/cpack.log"
  echo "FAIL: cpack"
  exit 1
fi
deb=$(ls "$out"/cpack/steadyxr_*_amd64.deb 2>/dev/null | head -n 1)
[[ -f $deb ]] || { echo "FAIL: no steadyxr_<version>_amd64.deb in $out/cpack"; ls "$out/cpack"; exit 1; }
echo "package: $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB)"
version=$(dpkg-deb -f "$deb" Version)
[[ $(basename "$deb") == "steadyxr_${version}_amd64.deb" ]] || fail "file name $(basename "$deb") does not carry version $version"
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for lib in libc6 libstdc++6 libvulkan1; do
  [[ $depends == *"$lib"* ]] || fail "Depends lacks $lib (dpkg-shlibdeps not run?)"
done

# 2. What it holds: paths a user and the OpenXR loader look in.
dpkg-deb -c "$deb" | awk '{print $NF}' | sed 's|^\./|/|' >"$out/contents.txt"
libdir=/usr/lib/x86_64-linux-gnu
for path in "$libdir/openxr/1/api_layers/libXrApiLayer_steadyxr.so" \
  /usr/share/openxr/1/api_layers/explicit.d/XrApiLayer_steadyxr.json \
  /usr/share/openxr/1/api_layers/implicit.d/XrApiLayer_steadyxr.json \
  /usr/bin/steadyxr /usr/bin/steadyxr-imu-emu /usr/share/doc/steadyxr/examples/steadyxr.conf \
  /usr/share/doc/steadyxr/README.md /usr/share/doc/steadyxr/copyright /usr/share/man/man1/steadyxr.1.gz \
  /usr/share/man/man1/steadyxr-imu-emu.1.gz; do
  grep -qxF "$path" "$out/contents.txt" || fail "the package lacks $path"
done

# 3. Install into an overlay of the cached trixie root (writes go to a scratch upper layer), or
#    into a copy of it: the shared cached root is never written.
source "$here/../layer/e2e/lib.sh"
base=$(e2e_root) || exit $?
scratch=$(mktemp -d /tmp/steadyxr-deb-XXXXXX)
root=$scratch/merged
mkdir -p "$scratch/upper" "$scratch/work" "$root"
pids=()
cleanup() {
  e2e_stop_pids
  umount "$root" 2>/dev/null || umount -l "$root" 2>/dev/null || true
  rm -rf "$scratch"
}
trap cleanup EXIT
if ! mount -t overlay overlay -o "lowerdir=$base,upperdir=$scratch/upper,workdir=$scratch/work" "$root" 2>"$out/mount.log"; then
  # No overlayfs here (a container without the capability): a copy does the same, slower.
  echo "no overlay ($(cat "$out/mount.log")): copying the root instead"
  rmdir "$root" && cp -a --reflink=auto "$base" "$root" || { echo "FAIL: cannot copy the trixie root"; exit 1; }
fi

cp "$deb" "$root/tmp/"
if ! chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin dpkg -i "/tmp/$(basename "$deb")" \
  >"$out/dpkg-install.log" 2>&1; then
  cat "$out/dpkg-install.log"
  fail "dpkg -i failed (do the Depends resolve in trixie?)"
  exit 1
fi
echo "installed: $(chroot "$root" dpkg-query -W -f='${Package} ${Version} ${Status}' steadyxr)"
chroot "$root" steadyxr --help >"$out/steadyxr-help.txt" 2>&1 || fail "steadyxr --help failed in the root"
chroot "$root" steadyxr-imu-emu --help >"$out/imu-emu-help.txt" 2>&1
grep -q "usage: steadyxr-imu-emu" "$out/imu-emu-help.txt" || fail "steadyxr-imu-emu --help printed no usage in the root"
chroot "$root" /usr/bin/env -i PATH=/usr/bin:/bin MANPAGER=cat man -P cat steadyxr >/dev/null 2>&1 ||
  [[ ! -x $root/usr/bin/man ]] || fail "man steadyxr failed"

# 4. A user's run: Monado + hello_xr, only STEADYXR_ENABLE=1 for the layer (no layer path, no config).
dir=/tmp/steadyxr-deb-run
mkdir -p "$root$dir/xdg"
chmod 700 "$root$dir/xdg"
env=(PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root XDG_RUNTIME_DIR=$dir/xdg
  VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/lvp_icd.json
  XR_RUNTIME_JSON=/usr/share/openxr/1/openxr_monado.json XRT_NO_STDIN=1 XRT_COMPOSITOR_NULL=1)
e2e_start_monado "$root" "$out/monado.log" "${env[@]}" || { fail "monado-service did not start"; exit 1; }
sleep "$seconds" | chroot "$root" /usr/bin/env -i "${env[@]}" STEADYXR_ENABLE=1 hello_xr -g Vulkan2 -vc Stereo \
  >"$out/hello_xr.log" 2>&1 &
app=$!
pids+=("$app")
# While it runs, the installed CLI must list the instance, filtering (the last such listing is
# kept: its means cover the most frames).
listed=0
while kill -0 "$app" 2>/dev/null; do
  chroot "$root" /usr/bin/env -i "${env[@]}" steadyxr status >"$out/status-now.txt" 2>&1
  if grep -q "HelloXR (pid [0-9]*): filtering" "$out/status-now.txt" &&
    grep -qE "frames: [1-9][0-9]* filtered" "$out/status-now.txt"; then
    listed=1
    mv "$out/status-now.txt" "$out/status.txt"
  fi
  sleep 0.5
done
wait "$app"
app_rc=$?
echo "steadyxr status during the run:"
sed 's/^/  /' "$out/status.txt" 2>/dev/null
((listed == 1)) || fail "steadyxr status did not list a filtering HelloXR"
((app_rc == 0)) || { tail -n 20 "$out/hello_xr.log"; fail "hello_xr exited $app_rc"; }
summary=$(grep -a "session summary:" "$out/hello_xr.log" | tail -n 1)
echo "layer: $summary"
filtered=$(sed -n 's/.*frames_filtered=\([0-9]*\).*/\1/p' <<<"$summary")
((${filtered:-0} >= 20)) || fail "the installed implicit layer filtered ${filtered:-no} frames (want >= 20)"
grep -aq "loaded for 'HelloXR': enabled" "$out/hello_xr.log" || fail "the layer did not announce itself"
left=$(ls -A "$root$dir/xdg/steadyxr" 2>/dev/null)
[[ -z $left ]] || fail "status files left after the app exited: $left"
cleanup_run() {
  kill -TERM "$e2e_monado_pid" 2>/dev/null
  wait "$e2e_monado_pid" 2>/dev/null
  pids=()
  rm -rf "${root:?}$dir"
}
cleanup_run

# 5. Purge: nothing of the package may be left.
if ! chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin dpkg --purge steadyxr >"$out/dpkg-purge.log" 2>&1; then
  cat "$out/dpkg-purge.log"
  fail "dpkg --purge failed"
fi
chroot "$root" dpkg-query -W steadyxr >/dev/null 2>&1 && fail "dpkg still knows steadyxr after --purge"
while read -r path; do
  [[ -z $path || $path == */ ]] && continue
  [[ -e $root$path || -L $root$path ]] && fail "left after purge: $path"
done <"$out/contents.txt"
leftovers=$(cd "$root" && find usr etc var/lib/dpkg/info -name '*steadyxr*' 2>/dev/null)
[[ -z $leftovers ]] || fail "left after purge: $leftovers"
[[ -e $root/usr/share/doc/steadyxr ]] && fail "left after purge: /usr/share/doc/steadyxr"

if ((failures > 0)); then
  echo "deb: $failures failure(s); logs in $out"
  exit 1
fi
echo "deb: PASS (built, installed, filtered $filtered frames with STEADYXR_ENABLE=1 only, purged clean); logs in $out"
