"""Runs steadyxr-eval for the CI scripts (run_small_suite.py, run_hud_small.py) and fails on a non-zero exit."""
import os
import subprocess
import sys


def run_eval(cmd, tail=3000):
    # Under the sanitizer build, leak reports would come from the Vulkan driver's (Mesa/LLVM)
    # process-lifetime allocations, not from steadyxr: keep ASan's error checks, drop leak checks.
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":")
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=200, env=env)
    print(res.stdout[-tail:])
    print(res.stderr[-tail:], file=sys.stderr)
    assert res.returncode == 0, f"steadyxr-eval exited {res.returncode}"
    return res
