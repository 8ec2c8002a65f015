#!/usr/bin/env bash
# End-to-end test of live control: one hello_xr run on Monado (real loader, lavapipe, inside the
# cached trixie root, as run_e2e.sh) while the test edits the layer's config file, the way a
# user does: with the `steadyxr` tool, with an editor's rename-on-save, and with a bad edit.
# Each phase is checked through the layer's own counters (its status file) and dumped frames:
#
#   A  method = none            output == input (dumped), frames filtered
#   B  steadyxr set method=default profile=hud dump_dir=...   applied live, output != input (dumped)
#   C  enabled = 0 (rename)     frames_filtered stops, frames_disabled grows
#   D  a bad edit (in place)    logged, the last good settings stay (still disabled)
#   E  steadyxr set enabled=1 method=none dump_dir=...   filtering again, output == input
#
#   run_live.sh LAYER_SO PNG_COMPARE STEADYXR_CLI OUT_DIR
# Exit: 0 pass, 1 fail, 77 skipped (no trixie root).
set -uo pipefail

layer_so=$(readlink -f "${1:?layer .so}")
png_compare=$(readlink -f "${2:?png_compare}")
cli=$(readlink -f "${3:?steadyxr cli}")
out=${4:?output dir}
here=$(cd "$(dirname "$0")" && pwd)
layer_name=XR_APILAYER_STEADYXR_head_taa

source "$here/lib.sh"
out=$(e2e_fresh_dir "$out") || exit 1
root=$(e2e_root) || exit $?

dir=/tmp/steadyxr-live-$$
host=$root$dir
mkdir -p "$host/xdg"
chmod 700 "$host/xdg"
e2e_install_layer "$host" "$dir" "$layer_so" "steadyxr (live-control test copy)"
conf=$host/steadyxr.conf
printf 'method = none\ndump_frames = 3\ndump_dir = %s/dump-a\n' "$dir" >"$conf"

pids=()
cleanup() {
  exec 7>&- 2>/dev/null
  e2e_stop_pids
}
trap 'cleanup; cp -r "$host" "$out/run" 2>/dev/null; rm -rf "$host"' EXIT

failures=0
fail() {
  echo "FAIL[$phase]: $*"
  failures=$((failures + 1))
}

env=(PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root XDG_RUNTIME_DIR=$dir/xdg
  VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/lvp_icd.json
  XR_RUNTIME_JSON=/usr/share/openxr/1/openxr_monado.json XRT_NO_STDIN=1 XRT_COMPOSITOR_NULL=1)
phase=start
e2e_start_monado "$root" "$out/monado.log" "${env[@]}" || { fail "monado-service did not start"; exit 1; }

# hello_xr runs until its standard input closes: a FIFO this script holds open (fd 7).
mkfifo "$host/stdin"
chroot "$root" /usr/bin/env -i "${env[@]}" XR_API_LAYER_PATH="$dir/layer" XR_ENABLE_API_LAYERS=$layer_name \
  STEADYXR_CONFIG="$dir/steadyxr.conf" hello_xr -g Vulkan2 -vc Stereo <"$host/stdin" >"$out/hello_xr.log" 2>&1 &
app=$!
pids+=("$app")
exec 7>"$host/stdin"

status_file() { e2e_status_file "$host/xdg"; }
field() { e2e_status_field "$host/xdg" "$1"; }
# wait_for SECONDS CONDITION: polls the status file until the shell condition holds.
wait_for() {
  local limit=$(($1 * 10)) i
  for ((i = 0; i < limit; i++)); do
    [[ -n $(status_file) ]] && eval "$2" && return 0
    kill -0 "$app" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}
now_ms() { date +%s%3N; }
# check_dump FOLDER equal|differ
check_dump() {
  local n=0 same=0 in
  for in in "$host/$1"/*_in.png; do
    [[ -f $in ]] || continue
    n=$((n + 1))
    "$png_compare" equal "$in" "${in%_in.png}_out.png" >/dev/null && same=$((same + 1))
  done
  ((n >= 2)) || { fail "only $n dumped eye images in $1"; return; }
  if [[ $2 == equal ]]; then
    ((same == n)) || fail "$1: output differs from input in $((n - same)) of $n eye images (method none)"
  else
    ((same < n)) || fail "$1: output equals input in all $n eye images (the filter did not run)"
  fi
  echo "[$phase] $1: $n dumped eye images, $same with output == input"
}
applied_after() { # the status's config_applied_unix_ms minus the write time $1
  echo $(($(field config_applied_unix_ms) - $1))
}
# Wait for the dumps to be written (the dumper writes the next N filtered frames).
wait_dump() { for _ in $(seq 100); do (($(ls "$host/$1"/*_out.png 2>/dev/null | wc -l) >= 6)) && return; sleep 0.1; done; }

# --- A: method none from the start.
phase=A
wait_for 60 '[[ $(field state) == filtering && $(field frames_filtered) -ge 10 ]]' ||
  { fail "no filtering within 60 s: $(cat "$(status_file)" 2>/dev/null)"; tail "$out/hello_xr.log"; exit 1; }
[[ $(field method) == none ]] || fail "method $(field method), want none"
wait_dump dump-a
check_dump dump-a equal
echo "[$phase] method=$(field method) frames_filtered=$(field frames_filtered)"

# --- B: the CLI switches to the default method; dumps re-armed into a new folder.
phase=B
t=$(now_ms)
"$cli" --config "$conf" set method=default profile=hud "dump_dir=$dir/dump-b" >"$out/cli-b.txt" 2>&1 || fail "steadyxr set: $(cat "$out/cli-b.txt")"
wait_for 10 '[[ $(field method) == default && $(field passes) == steady && $(field profile) == hud ]]' ||
  fail "method default with profile hud not applied: method $(field method), profile $(field profile)"
latency_b=$(applied_after "$t")
base=$(field frames_filtered)
wait_for 30 "[[ \$(field frames_filtered) -ge $((base + 10)) ]]" || fail "filtering stopped after the method change"
# The default's pipelines were never asked for in this process (A ran none): the first frames after the
# switch wait for them, counted apart from the start's.
late_b=$(field frames_warming_up_late)
((${late_b:-0} >= 1)) || fail "frames_warming_up_late=${late_b:-none} after a switch to new pipelines, want >= 1"
wait_dump dump-b
check_dump dump-b differ
echo "[$phase] applied $latency_b ms after the write; method=$(field method) passes=$(field passes) profile=$(field profile); ${late_b:-?} frames waited for its pipelines"

# --- C: an editor's save (write a new file, rename it over the config) disables filtering.
phase=C
t=$(now_ms)
printf 'method = default\ndump_frames = 3\ndump_dir = %s/dump-b\nenabled = 0\n' "$dir" >"$conf.swp"
mv "$conf.swp" "$conf"
wait_for 10 '[[ $(field enabled) == 0 && $(field state) == disabled ]]' || fail "enabled = 0 not applied"
latency_c=$(applied_after "$t")
sleep 1.2  # the status is rewritten about once a second
filtered_c=$(field frames_filtered)
disabled_c=$(field frames_disabled)
sleep 2.2
filtered_c2=$(field frames_filtered)
disabled_c2=$(field frames_disabled)
((filtered_c2 == filtered_c)) || fail "frames_filtered grew while disabled ($filtered_c -> $filtered_c2)"
((disabled_c2 >= disabled_c + 10)) || fail "frames_disabled grew only $disabled_c -> $disabled_c2 in 2 s"
echo "[$phase] applied $latency_c ms after the rename; frames_filtered $filtered_c -> $filtered_c2, frames_disabled $disabled_c -> $disabled_c2"

# --- D: a bad edit, written in place: logged, and the last good settings stay.
phase=D
gen=$(field config_generation)
printf 'method = sharpen\nenabled = 1\n' >"$conf"
for _ in $(seq 50); do grep -aq "keeping the last good settings" "$out/hello_xr.log" && break; sleep 0.1; done
grep -aq "method = sharpen (config file)" "$out/hello_xr.log" || fail "the bad value was not logged"
grep -aq "not applied; keeping the last good settings" "$out/hello_xr.log" || fail "no 'keeping the last good settings' line"
sleep 1.2
[[ $(field enabled) == 0 && $(field config_generation) == "$gen" ]] || fail "the bad edit changed the settings"
echo "[$phase] bad edit refused: enabled=$(field enabled) generation $(field config_generation)"

# --- E: the CLI switches filtering back on with method none (it also fixes the bad line).
phase=E
t=$(now_ms)
"$cli" --config "$conf" set enabled=1 method=none dump_frames=3 "dump_dir=$dir/dump-e" >"$out/cli-e.txt" 2>&1 ||
  fail "steadyxr set: $(cat "$out/cli-e.txt")"
wait_for 10 '[[ $(field enabled) == 1 && $(field method) == none && $(field state) == filtering ]]' || fail "re-enable not applied"
latency_e=$(applied_after "$t")
base=$(field frames_filtered)
wait_for 30 "[[ \$(field frames_filtered) -ge $((base + 10)) ]]" || fail "frames_filtered did not grow after re-enabling"
wait_dump dump-e
check_dump dump-e equal
echo "[$phase] applied $latency_e ms after the write; frames_filtered $base -> $(field frames_filtered)"

# --- End: close hello_xr's input; the summary and the status file's removal.
phase=end
exec 7>&-
timeout 60 tail --pid="$app" -f /dev/null
wait "$app"
app_rc=$?
((app_rc == 0)) || { fail "hello_xr exited $app_rc"; tail -n 20 "$out/hello_xr.log"; }
summary=$(grep -a "session summary:" "$out/hello_xr.log" | tail -n 1)
echo "[$phase] $summary"
late=$(sed -n 's/.*frames_warming_up_late=\([0-9]*\).*/\1/p' <<<"$summary")
((${late:-0} >= ${late_b:-0})) || fail "summary frames_warming_up_late=${late:-none}, the status file said ${late_b:-none}"
disabled=$(sed -n 's/.*frames_disabled=\([0-9]*\).*/\1/p' <<<"$summary")
((${disabled:-0} >= 10)) || fail "summary frames_disabled=${disabled:-none}"
applied=$(grep -ac "config: applied" "$out/hello_xr.log")
((applied == 3)) || fail "$applied 'config: applied' lines, want 3 (B, C, E)"
[[ -z $(status_file) ]] || fail "the status file outlived the app: $(status_file)"
echo "live latency_ms B=$latency_b C=$latency_c E=$latency_e" >>"$out/results.txt"

if ((failures > 0)); then
  echo "live: $failures failure(s); logs in $out"
  exit 1
fi
echo "live: PASS (config applied ${latency_b}/${latency_c}/${latency_e} ms after the write); logs in $out"
