#!/usr/bin/env bash
# End-to-end test of the steadyxr OpenXR layer: real OpenXR loader, real Monado 25, real
# hello_xr 1.1.47, real Vulkan (lavapipe), with Khronos' core_validation layer behind ours.
# Everything runs inside a cached Debian trixie root (see ensure_root.sh).
#
#   run_e2e.sh LAYER_SO PNG_COMPARE OUT_DIR [IMU_EMULATOR]
#
# With IMU_EMULATOR (steadyxr-imu-emu) a further run uses pose_source = imu, fed by the
# emulator over a Unix socket, and checks that the head speed came from the IMU.
#
# Environment: STEADYXR_CACHE_DIR (root cache, default ~/.cache/steadyxr), STEADYXR_E2E_SECONDS
# (length of each hello_xr run, default 10), STEADYXR_E2E_XVFB=0 skips the main-compositor run,
# STEADYXR_E2E_CASES="jitter none ..." runs only the named cases (default: all).
# Exit: 0 pass, 1 fail, 77 skipped (no debootstrap / no Debian mirror).
set -uo pipefail

layer_so=$(readlink -f "${1:?layer .so}")
png_compare=$(readlink -f "${2:?png_compare}")
out=${3:?output dir}
imu_emu=${4:-}
[[ -z $imu_emu ]] || imu_emu=$(readlink -f "$imu_emu")
seconds=${STEADYXR_E2E_SECONDS:-10}
here=$(cd "$(dirname "$0")" && pwd)
layer_name=XR_APILAYER_STEADYXR_head_taa

source "$here/lib.sh"
out=$(e2e_fresh_dir "$out") || exit 1
root=$(e2e_root) || exit $?

# Per-run folder inside the root (no bind mounts): the layer, its manifest, logs, dumps.
tag=steadyxr-e2e-$$
inroot=/tmp/$tag
host=$root$inroot
e2e_install_layer "$host" "$inroot" "$layer_so" "steadyxr (end-to-end test copy)"

# The implicit manifest, found through XDG_DATA_DIRS, enabled only by STEADYXR_ENABLE.
mkdir -p "$host/data/openxr/1/api_layers/implicit.d"
cat >"$host/data/openxr/1/api_layers/implicit.d/XrApiLayer_steadyxr.json" <<JSON
{
    "file_format_version": "1.0.0",
    "api_layer": {
        "name": "$layer_name",
        "library_path": "$inroot/layer/$(basename "$layer_so")",
        "api_version": "1.0",
        "implementation_version": "1",
        "description": "steadyxr (end-to-end test copy, implicit)",
        "enable_environment": "STEADYXR_ENABLE",
        "disable_environment": "STEADYXR_DISABLE"
    }
}
JSON

pids=()
cleanup() {
  e2e_stop_pids
}
cleanup_all() {
  cleanup
  rm -rf "$host"
}
trap cleanup_all EXIT

missing=$(chroot "$root" /usr/bin/ldd "$inroot/layer/$(basename "$layer_so")" 2>&1 | grep "not found" || true)
if [[ -n $missing ]]; then
  echo "FAIL: the layer cannot load inside the trixie root: $missing"
  exit 1
fi

base_env=(PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json
  VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/lvp_icd.json XR_RUNTIME_JSON=/usr/share/openxr/1/openxr_monado.json
  XRT_NO_STDIN=1)
failures=0
fail() {
  echo "FAIL[$case_name]: $*"
  failures=$((failures + 1))
}

# run_case NAME METHOD COMPOSITOR(null|xcb) DUMP_FRAMES MIN_FRAMES_PER_EYE
run_case() {
  case_name=$1
  if [[ -n ${STEADYXR_E2E_CASES:-} && " $STEADYXR_E2E_CASES " != *" $case_name "* ]]; then
    selected=0
    return
  fi
  selected=1
  local method=$2 compositor=$3 dump=$4 min_frames=$5
  local dir=$inroot/$case_name hdir=$host/$case_name
  mkdir -p "$hdir/xdg" "$hdir/dump"
  chmod 700 "$hdir/xdg"
  local env=("${base_env[@]}" XDG_RUNTIME_DIR=$dir/xdg)
  local layer_env=() layer_path="$inroot/layer:/usr/share/openxr/1/api_layers/explicit.d"
  local enable="$layer_name:XR_APILAYER_LUNARG_core_validation"
  if [[ $case_name == implicit* ]]; then
    layer_path=/usr/share/openxr/1/api_layers/explicit.d
    enable=XR_APILAYER_LUNARG_core_validation
    layer_env=(XDG_DATA_DIRS=$inroot/data:/usr/share)
    [[ $case_name == implicit_off ]] || layer_env+=(STEADYXR_ENABLE=1)
  fi
  local run_seconds=$seconds
  if [[ $case_name == disabled ]]; then
    layer_env=(STEADYXR_ENABLED=0)
  fi
  if [[ $case_name == disabled || $case_name == implicit_off ]]; then run_seconds=3; fi
  if [[ $case_name == jitter ]]; then
    layer_env=(STEADYXR_JITTER=1)
    # ~120 frames at the null compositor's 20 Hz on a quiet machine. Round 13's clean-clone run had
    # a slow spell in which 4 s gave 20 frames, 38 jittered views against the 40 checked below.
    run_seconds=6
  fi
  if [[ $case_name == xvfb ]]; then
    # Frames that wait for the pipelines pass at the compositor's ~55 Hz, filtered ones at lavapipe's
    # ~10 Hz at 896x1007: in 10 s a 1.6 s compile gave 88 waiting against 79 filtered (round 17, one
    # local run of several, the others 46-54 against 96-99). 14 s keeps the check about the session.
    run_seconds=14
  fi
  if [[ $case_name == imu ]]; then
    "$imu_emu" --motion pursuit --duration 600 --out "socket:$hdir/imu.sock" >"$hdir/imu-emu.log" 2>&1 &
    pids+=($!)
    for _ in $(seq 50); do [[ -S $hdir/imu.sock ]] && break; sleep 0.1; done
    layer_env=(STEADYXR_POSE_SOURCE=imu STEADYXR_IMU_DEVICE=socket:$dir/imu.sock)
  fi
  if [[ $compositor == xcb ]]; then
    local display=:$((90 + $$ % 9))
    chroot "$root" /usr/bin/env -i "${env[@]}" Xvfb "$display" -screen 0 1920x1080x24 -nolisten tcp \
      >"$hdir/xvfb.log" 2>&1 &
    pids+=($!)
    sleep 1
    env+=(DISPLAY=$display XRT_COMPOSITOR_FORCE_XCB=1)
  else
    env+=(XRT_COMPOSITOR_NULL=1)
  fi
  if ! e2e_start_monado "$root" "$hdir/monado.log" "${env[@]}"; then
    fail "monado-service did not start"
    cleanup
    return
  fi
  # hello_xr exits cleanly when its standard input closes: a clean run of at least N seconds, and
  # longer (up to 30 s more, 3 min over the six cases at most) until the layer has filtered a quarter
  # more frames than the case checks, in a quarter more time than frames waited for its pipelines
  # (the checks below). Round 21's first clean-clone CI had a slow spell of the machine in which the
  # jitter case filtered 8 frames in its 6 s (294 ms a frame; 97 on a quiet machine) and failed a
  # check of its bookkeeping.
  local compositor_hz=20
  [[ $compositor == xcb ]] && compositor_hz=55
  local want_frames=$(((min_frames * 5 + 3) / 4))
  { sleep "$run_seconds"; e2e_wait_for_frames "$hdir/xdg" "$want_frames" "$compositor_hz" 30; } |
    timeout --kill-after=10 $((run_seconds + 120)) chroot "$root" /usr/bin/env -i "${env[@]}" \
    XR_API_LAYER_PATH="$layer_path" XR_ENABLE_API_LAYERS="$enable" \
    XR_CORE_VALIDATION_EXPORT_TYPE=text XR_CORE_VALIDATION_FILE_NAME="$dir/core_validation.txt" \
    "${layer_env[@]}" STEADYXR_METHOD="$method" STEADYXR_DUMP_FRAMES="$dump" STEADYXR_DUMP_DIR="$dir/dump" STEADYXR_LOG_LEVEL=${STEADYXR_E2E_LOG_LEVEL:-info} \
    hello_xr -g Vulkan2 -vc Stereo >"$hdir/hello_xr.log" 2>&1
  local app_rc=${PIPESTATUS[1]}
  cleanup
  cp -r "$hdir" "$out/"

  local summary
  summary=$(grep -a "session summary:" "$hdir/hello_xr.log" | tail -n 1)
  if [[ $case_name == implicit_off ]]; then
    ((app_rc == 0)) || fail "hello_xr exited $app_rc"
    if grep -aq "\[steadyxr\]" "$hdir/hello_xr.log"; then
      fail "the implicit layer loaded without STEADYXR_ENABLE"
    else
      echo "[$case_name] implicit layer stays out without STEADYXR_ENABLE (hello_xr exit $app_rc)"
    fi
    return
  fi
  if [[ $case_name == disabled ]]; then
    ((app_rc == 0)) || fail "hello_xr exited $app_rc"
    if grep -aq "\[steadyxr\] info: .*: disabled" "$hdir/hello_xr.log" && [[ -z $summary ]]; then
      echo "[$case_name] STEADYXR_ENABLED=0: layer loaded, hooked nothing (hello_xr exit $app_rc)"
    else
      fail "STEADYXR_ENABLED=0 did not start the layer disabled"
    fi
    return
  fi
  echo "[$case_name] hello_xr exit $app_rc; $summary"
  ((app_rc == 0)) || { fail "hello_xr exited $app_rc"; tail -n 30 "$hdir/hello_xr.log"; }
  [[ -n $summary ]] || { fail "no session summary from the layer (did it load?)"; return; }
  local filtered left right passed
  filtered=$(sed -n 's/.*frames_filtered=\([0-9]*\).*/\1/p' <<<"$summary")
  left=$(sed -n 's/.* left=\([0-9]*\).*/\1/p' <<<"$summary")
  right=$(sed -n 's/.* right=\([0-9]*\).*/\1/p' <<<"$summary")
  passed=$(sed -n 's/.*frames_passed_through=\([0-9]*\).*/\1/p' <<<"$summary")
  ((left >= min_frames && right >= min_frames)) ||
    fail "filtered too few frames (left=$left right=$right, want >= $min_frames)"
  ((passed == 0)) || fail "$passed frames passed through"
  # Pipelines compile in the background: the first frames pass through rather than stall. How
  # many is a timing figure, printed, not a pass mark (1-10 on a quiet 2-core machine, 52 of the
  # xvfb case's 125 with a second job on the same two cores); the check is that the filter took
  # over for most of the session's time. Frames are counted in time (e2e_session_times; lavapipe:
  # ~75 ms a filtered frame at xcb's 896x1007). Counted in frames, a 1.8 s compile gave 98 waiting
  # against 87 filtered in a 14 s session (round 18's clean clone).
  local warming late gpu_ms waiting_s filtered_s
  warming=$(sed -n 's/.*frames_warming_up=\([0-9]*\).*/\1/p' <<<"$summary")
  late=$(sed -n 's/.*frames_warming_up_late=\([0-9]*\).*/\1/p' <<<"$summary")
  gpu_ms=$(sed -n 's/.*gpu_ms_mean:.* total=\([0-9.]*\).*/\1/p' <<<"$summary")
  echo "[$case_name] ${warming:-no} frames passed through while the pipelines compiled, ${late:-?} of them after filtering began"
  # hello_xr asks for no new pipeline half-way: once filtered, every frame is (round 44's start-up bug
  # filtered and passed through in turn while one of the default's probes compiled).
  [[ ${late:-x} == 0 ]] || fail "${late:-no count of} frames waited for a pipeline after filtering had begun"
  read -r waiting_s filtered_s < <(e2e_session_times "${warming:-999999}" "$filtered" "${gpu_ms:-0}" "$compositor_hz")
  awk -v a="$waiting_s" -v b="$filtered_s" 'BEGIN { exit !(a < b) }' ||
    fail "${warming:-no} frames waited for the filter's pipelines (${waiting_s} s), $filtered filtered (${filtered_s} s at ${gpu_ms:-?} ms; want less time waiting)"
  local cv=$hdir/core_validation.txt
  if [[ ! -f $cv ]]; then
    fail "core_validation wrote no report (not loaded?)"
  elif grep -qE "VALID_ERROR" "$cv"; then
    fail "core_validation reported errors:"
    grep -E "VALID_ERROR" "$cv" | head -n 10
  else
    echo "[$case_name] core_validation: no errors ($(wc -l <"$cv") report lines)"
  fi
  if [[ $case_name == imu ]]; then
    local imu_frames
    imu_frames=$(sed -n 's/.*imu_frames=\([0-9]*\).*/\1/p' <<<"$summary")
    ((${imu_frames:-0} >= min_frames)) || fail "head speed came from the IMU in only ${imu_frames:-0} frames"
  fi
  if [[ $case_name == jitter ]]; then
    # Every view rendered with the layer's jitter must come back with it: filtered on and
    # submitted with the unjittered fov. Only the first frame (before the layer knows the view
    # size, so before it jitters) and a view located but not submitted at exit may differ.
    local applied undone unmatched
    applied=$(sed -n 's/.*jitter_views: applied=\([0-9]*\).*/\1/p' <<<"$summary")
    undone=$(sed -n 's/.*jitter_views: .*undone=\([0-9]*\).*/\1/p' <<<"$summary")
    unmatched=$(sed -n 's/.*jitter_views: .*unmatched=\([0-9]*\).*/\1/p' <<<"$summary")
    if [[ -z $undone ]]; then
      fail "no jitter counters in the session summary (jitter not active?)"
    else
      ((undone >= 40)) || fail "jitter undone on only $undone views (want >= 40)"
      ((applied - undone <= 2)) || fail "jitter applied on $applied views but undone on only $undone"
      ((unmatched <= 2)) || fail "$unmatched filtered views did not carry the layer's jitter"
      grep -aq "jitter: undone on submit" "$hdir/hello_xr.log" || fail "no 'jitter: undone' log line"
      echo "[$case_name] jitter applied on $applied views, undone on $undone, unmatched $unmatched"
    fi
    echo "$case_name jitter_applied=${applied:-0} jitter_undone=${undone:-0} jitter_unmatched=${unmatched:-0}" >>"$out/results.txt"
  fi
  echo "$case_name filtered=$filtered left=$left right=$right passed=$passed rc=$app_rc" >>"$out/results.txt"
}

# Dumped frames: input and output of each eye.
check_equal() {
  local dir=$host/$1/dump n=0
  for in in "$dir"/*_in.png; do
    [[ -f $in ]] || continue
    n=$((n + 1))
    if ! r=$("$png_compare" equal "$in" "${in%_in.png}_out.png"); then
      fail "output differs from input with method none: $(basename "$in"): $r"
    fi
  done
  ((n > 0)) || fail "no dumped images"
  echo "[$1] method none: $n dumped eye images, output == input"
}

# check_changes CASE PERMILLE: the share of pixels (in 1/1000) allowed to differ from the
# input outside the region where the input changed.
check_changes() {
  local dir=$host/$1/dump limit=$2 n=0 differ_total=0 outside_total=0 changed_total=0 total=0
  for eye in left right; do
    local prevs=()
    for in in "$dir"/frame*_"$eye"_in.png; do
      [[ -f $in ]] || continue
      if ((${#prevs[@]} > 0)); then
        local r
        r=$("$png_compare" changes 2 2 "$in" "${in%_in.png}_out.png" "${prevs[@]}") || fail "png_compare failed on $in"
        echo "[$1] $(basename "$in"): $r"
        differ_total=$((differ_total + $(sed -n 's/.*differ=\([0-9]*\).*/\1/p' <<<"$r")))
        outside_total=$((outside_total + $(sed -n 's/.*outside=\([0-9]*\).*/\1/p' <<<"$r")))
        changed_total=$((changed_total + $(sed -n 's/.*changed=\([0-9]*\).*/\1/p' <<<"$r")))
        total=$((total + $(sed -n 's/.*total=\([0-9]*\).*/\1/p' <<<"$r")))
        n=$((n + 1))
      fi
      prevs+=("$in")
    done
  done
  ((n > 0)) || { fail "no dumped frame pairs"; return; }
  echo "[$1] over $n frame pairs: differ=$differ_total outside_changed_region=$outside_total changed=$changed_total pixels=$total" |
    tee -a "$out/results.txt"
  # Where the input did not change between frames, a converged temporal filter must not change it.
  ((outside_total * 1000 <= total * limit)) || fail "output differs from input outside the changing region ($outside_total of $total pixels)"
  if ((changed_total > 0 && differ_total == 0)); then
    fail "the input changed between frames but the default method never changed the output"
  fi
}

run_case none none null 8 40
((selected == 0)) || check_equal none
# Monado 25's simulated HMD always wobbles, and hello_xr draws one cube locked to the view: the
# pose-reprojected history of that cube's edges is wrong (a dynamic region for the filter), so
# a few pixels per frame may differ outside the changed region. The limit (5 per mille of all
# pixels) still catches a filter that shifts, blurs or corrupts the image.
run_case default default null 8 40
((selected == 0)) || check_changes default 5
# jitter = 1 with the default method: a short run (the jitter bookkeeping, not image quality).
run_case jitter default null 0 20
# The implicit manifest: loaded with STEADYXR_ENABLE=1, absent without it.
run_case implicit none null 0 20
run_case implicit_off none null 0 0
run_case disabled none null 0 0
if [[ -n $imu_emu ]]; then
  run_case imu default null 0 40
fi
if [[ ${STEADYXR_E2E_XVFB:-1} != 0 ]]; then
  # 896x1007 per eye: lavapipe filters only a few frames per second there.
  run_case xvfb default xcb 0 3
fi

if ((failures > 0)); then
  echo "e2e: $failures failure(s); logs in $out"
  exit 1
fi
echo "e2e: PASS; logs in $out"
