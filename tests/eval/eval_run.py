"""Runs steadyxr-eval for the CI scripts (run_small_suite.py, run_hud_small.py, ...) and fails on a non-zero exit."""
import json
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


def run_small_case(exe, folder, extra, motion):
    """One image-viewer case (the astronaut, 24 frames, none, taa and the default): its results.json."""
    cmd = [exe, "--out", folder, "--corpus", "--scenes", "imageviewer", "--motions", motion, "--images",
           "astronaut", "--frames", "24", "--methods", "none,taa,default", "--no-progress"] + extra
    run_eval(cmd, tail=1500)
    with open(os.path.join(folder, "results.json")) as f:
        return json.load(f)


def rows_of(doc):
    return {r["method"]: r for r in doc["results"]}


def assert_refused(exe, folder, args, message):
    """The eval stops with exit 2 and `message` on stderr for these arguments."""
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":")
    bad = subprocess.run([exe, "--out", folder] + args + ["--quick", "--no-progress"], capture_output=True,
                         text=True, timeout=60, env=env)
    assert bad.returncode == 2 and message in bad.stderr, (bad.returncode, bad.stderr)
