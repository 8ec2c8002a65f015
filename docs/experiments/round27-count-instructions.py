#!/usr/bin/env python3
"""Each method's cost on lavapipe as x86 instructions per stereo frame, counted by valgrind.

Round 27's experiment, not a tool the tests run (docs/cost.md, round 27): the figures it gave are there, and
so is how it failed. A one-off event on lavapipe's queue thread (llvmpipe compiling a shader at its first
dispatch) that lands in one run of a difference and not the other ruins that difference: with Mesa's shader
cache on, a shader changed since the last run compiled in the first run only (a figure 8x too high); with the
cache off, a 64x64 run gave a negative figure. Trust a figure only where several frame windows agree.

steadyxr-bench times the passes, but on a shared 2-core machine its ratios move by tens of percent
from run to run (docs/cost.md). Instructions retired do not. Lavapipe runs the command buffers on
its queue thread and, with llvmpipe on one thread (LP_NUM_THREADS=0), the shaders there too, while
the bench's own thread compiles, records, submits and waits. So this runs the bench under valgrind's
callgrind with a count per thread, at two frame counts, and takes the difference of the threads'
counts: start-up and pipeline compiles drop out, and where nothing else happens the same command counts the
same instructions to within about a thousandth. Mesa's shader cache is off unless --shader-cache, so that a
changed shader compiles in both runs; that did not prevent the 64x64 failure above. Round 27's figures were taken
with the cache on (--shader-cache), every shader already in it; with it off the same binary counted 1.6 % more for
the default at 256x256 (507.8 instructions a pixel against 499.9).

    copy per frame   = (W(none, b) - W(none, a)) / (2 (b - a))      (the bench runs the copy twice)
    method per frame = (W(none+M, b) - W(none+M, a)) / (b - a) - 2 copy

W is the work off the bench's thread: the passes. The bench's thread is left out: besides recording and
submitting it waits for the device, and how long it polls varies. It is a measure of work, not of time:
memory traffic and cache misses count for nothing. Compare methods with each other in the same run; the bench on the
machine itself says what they cost in time.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

LAVAPIPE_ICD = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json"
TOTALS = re.compile(r"^totals:\s+(\d+)", re.M)


def count(bench, size, methods, frames, shader_cache, bench_input):
    """The instructions callgrind counted off the bench's own thread in one bench run (lavapipe's threads)."""
    # Without the shader disk cache llvmpipe compiles every shader at its first dispatch, on the queue thread; with it,
    # only what no earlier run left in Mesa's cache, and the two runs of a difference must both compile or both not.
    env = dict(os.environ, LP_NUM_THREADS="0")
    if not shader_cache:
        env["MESA_SHADER_CACHE_DISABLE"] = "true"
    if os.path.exists(LAVAPIPE_ICD):
        env["VK_ICD_FILENAMES"] = LAVAPIPE_ICD
    with tempfile.TemporaryDirectory() as out:
        cmd = ["valgrind", "--tool=callgrind", "--separate-threads=yes", f"--callgrind-out-file={out}/threads",
               bench, "--sizes", size, "--methods", ",".join(methods), "--iterations", str(frames),
               "--warmup", "0", "--input", bench_input]
        run = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=3600)
        if run.returncode != 0:
            sys.exit(f"count_instructions: '{' '.join(cmd)}' failed (exit {run.returncode}):\n{run.stderr[-2000:]}")
        bench_thread, others = 0, 0
        names = sorted(n for n in os.listdir(out) if re.fullmatch(r"threads-\d+", n))
        for name in names:  # threads-01 is the bench's own (valgrind numbers threads from 1)
            with open(os.path.join(out, name)) as f:
                found = TOTALS.search(f.read())
            if not found:
                sys.exit(f"count_instructions: no totals in callgrind's {name}")
            if name.endswith("-01"):
                bench_thread += int(found.group(1))
            else:
                others += int(found.group(1))
        if bench_thread == 0 or others == 0:
            sys.exit(f"count_instructions: expected the bench's thread and lavapipe's, callgrind wrote {names}")
        return others


def per_frame(args, methods, first, last):
    """The passes' instructions per frame: the difference of two runs over their frames."""
    runs = [count(args.bench, args.size, methods, n, args.shader_cache, args.input) for n in (first, last)]
    return (runs[1] - runs[0]) / (last - first)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bench", required=True, help="the steadyxr-bench binary (not a sanitizer build)")
    ap.add_argument("--size", default="256x256", help="per-eye size (default 256x256)")
    ap.add_argument("--methods", default="taa,hybrid,hybrid+stereo,default",
                    help="as steadyxr-bench takes them; the copy (none) is always measured")
    ap.add_argument("--frames", default="2,4",
                    help="the two frame counts whose difference is measured (default 2,4: a method's first "
                         "frame has no history and takes another path)")
    ap.add_argument("--shader-cache", action="store_true",
                    help="leave Mesa's shader disk cache on (round 27's figures: every shader already in it)")
    ap.add_argument("--input", default="picture", choices=["picture", "flat"],
                    help="the bench's eye images (round 28; round 27's figures were taken with the only input "
                         "there was then, flat)")
    ap.add_argument("--repeat-copy", action="store_true",
                    help="measure the copy twice and print how far apart the two counts are")
    args = ap.parse_args()
    first, last = (int(x) for x in args.frames.split(","))
    if not 1 <= first < last:
        sys.exit("count_instructions: --frames A,B needs 1 <= A < B")
    width, height = (int(x) for x in args.size.lower().split("x"))
    pixels = 2 * width * height  # a stereo frame

    copy = per_frame(args, ["none"], first, last) / 2
    print(f"{args.size} per eye, frames {first} -> {last}, llvmpipe on one thread under valgrind")
    if args.repeat_copy:
        again = per_frame(args, ["none"], first, last) / 2
        print(f"copy measured twice: {copy:.0f} and {again:.0f} instructions a frame "
              f"(apart by {abs(again - copy) / copy:.2e} of it)")
    print("\n| method | instructions per stereo frame (millions) | per pixel | x copy |")
    print("|---|---|---|---|")
    print(f"| copy (none) | {copy / 1e6:.2f} | {copy / pixels:.1f} | 1.00 |")
    for m in (m for m in args.methods.split(",") if m and m != "none"):
        work = per_frame(args, ["none", m], first, last) - 2 * copy
        print(f"| {m} | {work / 1e6:.2f} | {work / pixels:.1f} | {work / copy:.2f} |", flush=True)


if __name__ == "__main__":
    main()
