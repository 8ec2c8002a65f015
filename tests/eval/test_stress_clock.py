#!/usr/bin/env python3
"""CI: eval/stress.py plans a trace long enough for an app that misses frames (--drop-fraction).

The eval's clock for --drop-frames P (eval/frame_clock.cpp) spreads a run's frames over more app periods,
and the eval refuses a trace that ends before the run does. stress.py plans each trace's length from its
copy of that clock (stress.eval_missed_periods). Checked against the real eval:
1. the copy counts the missed periods the eval reports in results.json, over rates, lengths and seeds;
2. held-out seed 84's cases 22 and 27 (48 and 40 frames at 30 Hz missing 16 periods each; before the fix
   their 2.1-s and 1.83-s traces ended before the run) now run: stress.py's own trace, the eval's own
   clock, on a 32-px image with `none` alone.
usage: test_stress_clock.py EVAL_DIR STEADYXR_EVAL OUT_DIR"""
import json
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, sys.argv[1])
import stress  # noqa: E402

eval_bin, out = sys.argv[2], Path(sys.argv[3])


def run_eval(out_dir, frames, drop, seed, app_hz, extra):
    cmd = [eval_bin, "--scenes", "imageviewer", "--methods", "none", "--resolution", "32x32",
           "--frames", str(frames), "--drop-frames", f"{drop:g}", "--seed", str(seed),
           "--app-hz", f"{app_hz:g}", "--display-hz", f"{app_hz:g}", "--warp-steps", "0",
           "--no-sweeps", "--no-progress", "--out", str(out_dir)] + extra
    # Under the sanitizer build, keep ASan's checks but not the leak reports of Mesa's process-lifetime
    # allocations (as stress.py does).
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":")
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    assert proc.returncode == 0, (" ".join(cmd), proc.stderr.strip().splitlines()[-1:])
    with open(out_dir / "results.json") as f:
        return json.load(f)["config"]["missed_periods"]


# 1. The copy of the clock, against the eval's own, where runs of three missed periods (the cap) are
#    likely (P 0.5, the most the eval takes) and where they are rare (P 0.05).
for frames, drop, seed in [(24, 0.3, 3), (48, 0.241, 22), (40, 0.05, 9), (33, 0.5, 1234567)]:
    missed = run_eval(out / "clock", frames, drop, seed, 30.0, ["--motions", "fixation"])
    assert missed == stress.eval_missed_periods(frames, drop, seed), (frames, drop, seed, missed)
    assert missed > 0, (frames, drop, seed)

# 2. Seed 84's cases that stopped the eval before: stress.py's trace now covers the run.
args = stress.parse_args(["--eval", eval_bin, "--out", str(out), "--seed", "84", "--cases", "30",
                          "--app-hz", "30,72,90", "--noise-fraction", "0.3", "--locomotion-fraction", "0.3",
                          "--drop-fraction", "0.3", "--no-mipmaps-fraction", "0.3", "--unorm-fraction", "0.3"])
for index in (22, 27):
    case = stress.write_case_inputs(stress.draw_case(84, index, args), out / "seed84")
    missed = run_eval(out / f"seed84-{index}", case["frames"], case["drop"], index, case["app_hz"],
                      ["--trace", case["trace"]])
    assert missed == 16, (index, missed)
print("stress.py's traces cover the eval's clock with missed frames")
