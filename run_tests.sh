#!/usr/bin/env bash
# The test command: installs dependencies, builds warning-free (-Werror), runs every test
# (real Vulkan on lavapipe with validation, the IMU suite, the layer's end-to-end run under a
# real OpenXR runtime), then builds and runs the unit tests again under ASan+UBSan.
set -euo pipefail
cd "$(dirname "$0")"
bash .ci/install-deps.sh
jobs=$(nproc)

cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSTEADYXR_WERROR=ON
cmake --build build -j"$jobs"
# In parallel over the cores (the GPU suite is sharded: tests/core); the runs under Monado are RUN_SERIAL.
ctest --test-dir build --output-on-failure -j"$jobs"

# Sanitizer build: everything but the end-to-end run (hello_xr and Monado are not instrumented).
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DSTEADYXR_SANITIZE=ON -DSTEADYXR_WERROR=ON
cmake --build build-asan -j"$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j"$jobs" -LE "e2e|bench"
