#!/bin/sh
# steadyxr-shader-stats on the default's own pipelines (as steadyxr-bench --pipelines prints them),
# compiled by Mesa RADV's compiler for an AMD GPU that is not there (null hardware): every pipeline
# gets a line with its registers. Skipped (77) without RADV's driver.
# usage: shader_stats_smoke.sh STEADYXR_BENCH STEADYXR_SHADER_STATS
set -eu
bench=$1
stats=$2
icd=/usr/share/vulkan/icd.d/radeon_icd.x86_64.json
if [ ! -f "$icd" ]; then
  echo "no RADV driver ($icd): skipped"
  exit 77
fi
pipelines=$("$bench" --sizes 64x64 --methods none,default --iterations 1 --warmup 0 --pipelines |
  sed -n 's/^pipeline of default: //p')
count=$(echo "$pipelines" | grep -c . || true)
if [ "$count" -lt 2 ]; then  # the probe and the temporal pass
  echo "the bench printed $count pipelines for the default, expected the probe and the temporal pass"
  exit 1
fi
# shellcheck disable=SC2086 # one argument per pipeline
out=$(RADV_FORCE_FAMILY=navi21 VK_ICD_FILENAMES="$icd" "$stats" --gpu-shape $pipelines)
echo "$out"
with_registers=$(echo "$out" | grep -c '| VGPRs [0-9]' || true)
if [ "$with_registers" -ne "$count" ]; then
  echo "$with_registers of $count pipelines have a register count"
  exit 1
fi
