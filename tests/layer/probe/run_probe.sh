#!/usr/bin/env bash
# End-to-end runs of the probe app (steadyxr-probe) on real Monado 25 + lavapipe in the cached
# Debian trixie root (tests/layer/e2e/ensure_root.sh), through the real OpenXR loader, with
# Khronos' core_validation layer behind steadyxr and the Vulkan validation layer in the app.
#
#   run_probe.sh LAYER_SO PROBE OUT_DIR
#
# Runs: v2 with method none (every case; dumped output == input in RGBA), v2 with the default
# method (alpha carried through the temporal and stereo passes; dynres: a render size that changes
# every frame and a rect that moves inside its image, the history kept across it), v2 with method none
# through a loading screen (the history dropped after frames without layers), the invalid xrEndFrame
# calls with and without steadyxr (same results required), and v1 (XR_KHR_vulkan_enable).
# Exit: 0 pass, 1 fail, 77 skipped (no trixie root could be built).
set -uo pipefail

layer_so=$(readlink -f "${1:?layer .so}")
probe=$(readlink -f "${2:?probe}")
out=${3:?output dir}
here=$(cd "$(dirname "$0")" && pwd)
layer_name=XR_APILAYER_STEADYXR_head_taa

source "$here/../e2e/lib.sh"
out=$(e2e_fresh_dir "$out") || exit 1
root=$(e2e_root) || exit $?

inroot=/tmp/steadyxr-probe-$$
host=$root$inroot
e2e_install_layer "$host" "$inroot" "$layer_so" "steadyxr (probe test copy)"
cp "$probe" "$host/layer/"

pids=()
cleanup() {
  e2e_stop_pids
}
trap 'cleanup; rm -rf "$host"' EXIT

for bin in "$(basename "$layer_so")" "$(basename "$probe")"; do
  missing=$(chroot "$root" /usr/bin/ldd "$inroot/layer/$bin" 2>&1 | grep "not found" || true)
  [[ -z $missing ]] || { echo "FAIL: $bin cannot load inside the trixie root: $missing"; exit 1; }
done

failures=0
fail() {
  echo "FAIL[$run_name]: $*"
  failures=$((failures + 1))
}

# run NAME LAYERS(steadyxr|none) METHOD PROBE-ARGS...: one Monado, one probe process.
run() {
  run_name=$1
  local layers=$2 method=$3
  shift 3
  local dir=$inroot/$run_name hdir=$host/$run_name
  mkdir -p "$hdir/xdg" "$hdir/dump"
  chmod 700 "$hdir/xdg"
  local env=(PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json
    VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/lvp_icd.json XR_RUNTIME_JSON=/usr/share/openxr/1/openxr_monado.json
    XRT_NO_STDIN=1 XDG_RUNTIME_DIR=$dir/xdg XRT_COMPOSITOR_NULL=1)
  if ! e2e_start_monado "$root" "$hdir/monado.log" "${env[@]}"; then
    fail "monado-service did not start"
    cleanup
    return
  fi
  local enable=XR_APILAYER_LUNARG_core_validation probe_args=("$@")
  if [[ $layers == steadyxr ]]; then
    enable="$layer_name:$enable"
    probe_args=(--layer "${probe_args[@]}")
  fi
  timeout --kill-after=10 120 chroot "$root" /usr/bin/env -i "${env[@]}" \
    XR_API_LAYER_PATH="$inroot/layer:/usr/share/openxr/1/api_layers/explicit.d" XR_ENABLE_API_LAYERS="$enable" \
    XR_CORE_VALIDATION_EXPORT_TYPE=text XR_CORE_VALIDATION_FILE_NAME="$dir/core_validation.txt" \
    VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation \
    STEADYXR_METHOD="$method" STEADYXR_DUMP_FRAMES=3 STEADYXR_DUMP_DIR="$dir/dump" STEADYXR_LOG_FILE="$dir/layer.log" \
    "$inroot/layer/$(basename "$probe")" "${probe_args[@]}" >"$hdir/probe.log" 2>&1
  local rc=$?
  cleanup
  cp -r "$hdir" "$out/"
  grep -E "^probe:|^case " "$hdir/probe.log" | sed "s/^/[$run_name] /"
  ((rc == 0)) || fail "the probe exited $rc"
  # Every case printed its line, and none failed.
  local expected=0 c
  for c in "$@"; do [[ $c == --* || $c =~ ^[0-9]+$ ]] || expected=$((expected + 1)); done
  local printed
  printed=$(grep -c "^case " "$hdir/probe.log")
  ((printed == expected)) || fail "$printed of $expected cases reported (crash?)"
  local vk_errors
  vk_errors=$(grep -c "Validation Error" "$hdir/probe.log")
  ((vk_errors == 0)) || { fail "$vk_errors Vulkan validation errors"; grep -m 5 "Validation Error" "$hdir/probe.log"; }
  if [[ -f $hdir/core_validation.txt ]] && grep -q "VALID_ERROR" "$hdir/core_validation.txt" && [[ $run_name != invalid* ]]; then
    fail "core_validation reported errors"
    grep -m 5 "VALID_ERROR" "$hdir/core_validation.txt"
  fi
}

cases=(per_eye array sbs alpha unpremultiplied depth multi unorm fp16 resize dynres)
run v2_none steadyxr none --bit-exact "${cases[@]}"
# The default method's pipelines take longer to compile on lavapipe: more frames.
run v2_default steadyxr default --frames 40 alpha sbs depth dynres
# A loading screen (frames without layers): the frame after it starts without the history. Method
# none, whose one small pipeline is ready by the second frame even on a loaded machine, so that the
# layer filters before the loading screen (the history's effect on pixels: SessionTest.HistoryIs*).
run v2_loading steadyxr none --frames 32 loading
run invalid_with_layer steadyxr default invalid
run invalid_without_layer none default invalid
with=$(sed -n 's/^case invalid ok//p' "$host/invalid_with_layer/probe.log" 2>/dev/null || true)
without=$(sed -n 's/^case invalid ok//p' "$host/invalid_without_layer/probe.log" 2>/dev/null || true)
run_name=invalid
if [[ -z $with || $with != "$without" ]]; then
  fail "invalid calls: with steadyxr [$with], without [$without]"
else
  echo "[invalid] same results with and without steadyxr:$with"
fi
run v1 steadyxr none --bit-exact --v1 per_eye sbs

if ((failures > 0)); then
  echo "probe: $failures failure(s); logs in $out"
  exit 1
fi
echo "probe: PASS; logs in $out"
