#!/usr/bin/env bash
# The main job: installs dependencies, builds, and runs the evaluation harness's default suite
# (rendered scenes, simulated head motion, every method, speed and accuracy) into ./out.
# Extra arguments go to steadyxr-eval (see `build/eval/steadyxr-eval --help`).
set -euo pipefail
cd "$(dirname "$0")"
bash .ci/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target steadyxr-eval
./build/eval/steadyxr-eval --out out "$@"
python3 eval/plot.py out
