# Shared by the end-to-end scripts (run_e2e.sh, run_live.sh, probe/run_probe.sh,
# tests/packaging/deb_test.sh): the cached trixie root, a test copy of the layer inside it, and
# stopping what a script started. Source it; it defines functions only.

e2e_lib_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

# e2e_fresh_dir DIR: empties (or creates) DIR for this run's output and prints its absolute path.
e2e_fresh_dir() {
  rm -rf "$1" && mkdir -p "$1" && readlink -f "$1"
}

# Prints the cached trixie root's path, or exits the calling script: 77 (skip) where no root can
# be built here (no debootstrap, not root, no Debian mirror), 1 where building it failed.
e2e_root() {
  local root rc
  root=$("$e2e_lib_dir/ensure_root.sh")
  rc=$?
  if ((rc == 77)); then
    echo "SKIP: cannot build the trixie root (no debootstrap, not root, or no Debian mirror)" >&2
    exit 77
  elif ((rc != 0)) || [[ ! -d $root ]]; then
    echo "FAIL: building the trixie root failed" >&2
    exit 1
  fi
  echo "$root"
}

# e2e_install_layer HOST_DIR IN_ROOT_DIR LAYER_SO DESCRIPTION: copies the layer into
# HOST_DIR/layer (the root's IN_ROOT_DIR/layer) beside an explicit manifest naming it there.
e2e_install_layer() {
  local host=$1 inroot=$2 layer_so=$3 description=$4
  mkdir -p "$host/layer"
  cp "$layer_so" "$host/layer/"
  cat >"$host/layer/XrApiLayer_steadyxr.json" <<JSON
{
    "file_format_version": "1.0.0",
    "api_layer": {
        "name": "XR_APILAYER_STEADYXR_head_taa",
        "library_path": "$inroot/layer/$(basename "$layer_so")",
        "api_version": "1.0",
        "implementation_version": "1",
        "description": "$description"
    }
}
JSON
}

# Stops only what the script started, by PID (the array `pids`): TERM, up to 5 s, then KILL.
e2e_stop_pids() {
  local pid
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  done
  pids=()
}

# e2e_start_monado ROOT LOG ENV...: starts monado-service inside ROOT with exactly the
# environment ENV (its pid joins `pids` and is left in `e2e_monado_pid`) and waits up to 30 s for it to say it has started.
# Returns 1, after printing the log's tail, when it did not.
e2e_start_monado() {
  local root=$1 log=$2
  shift 2
  chroot "$root" /usr/bin/env -i "$@" monado-service >"$log" 2>&1 &
  e2e_monado_pid=$!
  pids+=("$e2e_monado_pid")
  for _ in $(seq 300); do
    grep -q "The Monado service has started" "$log" && return 0
    kill -0 "$e2e_monado_pid" 2>/dev/null || break
    sleep 0.1
  done
  grep -q "The Monado service has started" "$log" && return 0
  tail -n 20 "$log"
  return 1
}

# e2e_status_file XDG_DIR: the layer's status file ($XDG_RUNTIME_DIR/steadyxr/*.status, rewritten as it
# filters), empty when there is none yet. e2e_status_field XDG_DIR KEY: one of its fields.
e2e_status_file() { find "$1/steadyxr" -name "*.status" 2>/dev/null | head -n 1; }
e2e_status_field() { sed -n "s/^$2=//p" "$(e2e_status_file "$1")" 2>/dev/null | head -n 1; }

# e2e_session_times WARMING FILTERED GPU_MS COMPOSITOR_HZ: prints the seconds the session spent on frames
# that waited for the filter's pipelines and on filtered frames. A waiting frame passes at the compositor's
# rate (shared/notes: the null compositor 20 Hz, xcb about 55 Hz); a filtered one takes at least the
# filter's GPU time.
e2e_session_times() {
  awk -v w="${1:-999999}" -v f="${2:-0}" -v ms="${3:-0}" -v hz="$4" \
    'BEGIN { frame = 1 / hz; if (ms / 1000 > frame) frame = ms / 1000; printf "%.3f %.3f\n", w / hz, f * frame }'
}

# e2e_wait_for_frames XDG_DIR FRAMES COMPOSITOR_HZ SECONDS: returns once the layer's status file under
# XDG_DIR (e2e_status_file) counts FRAMES filtered frames and
# they took a quarter more time than the frames that waited for the pipelines (e2e_session_times), or
# after SECONDS. A run's length then follows the machine: a slow spell lengthens it instead of failing
# checks that are about the session, not its speed.
e2e_wait_for_frames() {
  local filtered warming gpu_ms times deadline=$((SECONDS + $4))
  while ((SECONDS < deadline)); do
    filtered=$(e2e_status_field "$1" frames_filtered)
    warming=$(e2e_status_field "$1" frames_warming_up)
    gpu_ms=$(e2e_status_field "$1" gpu_ms_total)
    times=$(e2e_session_times "${warming:-0}" "${filtered:-0}" "${gpu_ms:-0}" "$3")
    if ((${filtered:-0} >= $2)) && awk -v t="$times" 'BEGIN { split(t, s, " "); exit !(s[2] >= 1.25 * s[1]) }'; then
      return 0
    fi
    sleep 0.5
  done
  return 0
}
