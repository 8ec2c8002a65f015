#!/bin/sh
# The device check: what a session lent a GPU measures, as one short run within the device tool's limits
# (docs/cost.md). steadyxr-bench at three per-eye sizes, on the rendered picture and on the old flat input,
# the default beside the limit (hybrid+stereo) and without each of its dearest parts; then the
# driver's own register and instruction counts of the default's pipelines (steadyxr-shader-stats, where the
# driver reports pipeline statistics). The last lines printed are the summary: the median ratio to the copy
# over the runs, per input, size and method. OUT gets two files, since the device tool returns at most 8:
# summary.txt and device_check.tar.gz (every table and CSV, the driver's statistics, vulkaninfo and, where
# nvidia-smi runs, the GPU's clocks every 200 ms: a GPU's clock falls between short submissions, round 29).
# usage: eval/device_check.sh [--quick] [DIR]
#   DIR: a build folder (default build), or a folder holding the two binaries themselves, as a session
#        carries them to the device machine when it has no compiler there
#   --quick: one small run, to check the script itself on any device (CI runs it on lavapipe)
set -eu
quick=0
if [ "${1:-}" = "--quick" ]; then
  quick=1
  shift
fi
build=${1:-build}
out=${OUT:-/tmp/steadyxr-device-check}
work=$(mktemp -d)
clocks=
trap 'rm -rf "$work"; [ -z "$clocks" ] || kill "$clocks" 2>/dev/null' EXIT
bench=$build/layer/core/bench/steadyxr-bench
stats=$build/layer/core/bench/steadyxr-shader-stats
if [ -x "$build/steadyxr-bench" ]; then
  bench=$build/steadyxr-bench
  stats=$build/steadyxr-shader-stats
fi
for tool in "$bench" "$stats"; do
  if [ ! -x "$tool" ]; then
    echo "device_check: $tool is not built (cmake --build $build --target steadyxr-bench steadyxr-shader-stats)" >&2
    exit 2
  fi
done
if [ "$quick" = 1 ]; then
  sizes=64x64 iterations=2 warmup=1 runs=1
else
  # A headset's eyes (1440x1600 a Quest 2's render target at 1.0, 2064x2208 at 1.3) and round 21's 1024^2.
  sizes=1024x1024,1440x1600,2064x2208 iterations=200 warmup=50 runs=3
fi
methods=none,taa,hybrid,hybrid+stereo,default,default@hold=0,default@gain=0,default@noisy=0,default@blurnoise=0
mkdir -p "$out"
{ vulkaninfo --summary 2>&1 || echo "no vulkaninfo"; } > "$work/device.txt"
if nvidia-smi --query-gpu=name,driver_version --format=csv > "$work/gpu.txt" 2>/dev/null; then
  nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,pstate,power.draw --format=csv -lms 200 \
    > "$work/clocks.csv" 2>&1 &
  clocks=$!
else
  rm -f "$work/gpu.txt"
fi
# Rows each run's CSV must hold: a copy and every other method, at every size.
rows_per_run=$(( $(echo "$methods" | tr ',' '\n' | grep -cv '^none$') + 1 ))
rows_per_run=$((rows_per_run * $(echo "$sizes" | tr ',' '\n' | grep -c .)))
run=1
while [ "$run" -le "$runs" ]; do
  for input in picture flat; do
    "$bench" --sizes "$sizes" --methods "$methods" --iterations "$iterations" --warmup "$warmup" \
      --input "$input" --csv "$work/bench_${input}_$run.csv" > "$work/bench_${input}_$run.txt"
    rows=$(($(wc -l < "$work/bench_${input}_$run.csv") - 1))
    if [ "$rows" -ne "$rows_per_run" ]; then
      echo "device_check: bench_${input}_$run.csv holds $rows rows, expected $rows_per_run" >&2
      exit 1
    fi
  done
  run=$((run + 1))
done
pipelines=$("$bench" --sizes 64x64 --methods default,hybrid+stereo --iterations 1 --warmup 0 --pipelines |
  sed -n 's/^pipeline of [^:]*: //p' | sort -u)
# shellcheck disable=SC2086 # one argument per pipeline
if ! "$stats" $pipelines > "$work/shader_stats.txt" 2>&1; then
  echo "device_check: no pipeline statistics from this device's driver (shader_stats.txt)"
fi
{
  echo "median ratio to the copy over $runs run(s) (GPU timestamps; bench_*.csv in device_check.tar.gz):"
  for input in picture flat; do
    cat "$work"/bench_"$input"_*.csv | awk -F, -v input="$input" '
      $1 != "width" { key = $1 "x" $2 " " $3; n[key]++; v[key, n[key]] = $6 }
      END {
        for (key in n) {
          m = n[key]
          for (i = 1; i <= m; i++) s[i] = v[key, i]
          for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++) if (s[j] < s[i]) { t = s[i]; s[i] = s[j]; s[j] = t }
          printf "%s %s %.2f\n", input, key, s[int((m + 1) / 2)]
        }
      }' | sort
  done
} | tee "$out/summary.txt"
cp "$out/summary.txt" "$work/"
tar -C "$work" -czf "$out/device_check.tar.gz" .
