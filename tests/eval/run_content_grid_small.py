#!/usr/bin/env python3
"""CI: eval/content_grid.py on a small grid (fade and video under tremor over the zone plate, 30 Hz, 1 s).

The default keeps the promise there (--check default exits 0); plain taa lags content that changes in
place, so the grid must find it above none with frames above 1.10x that are not none's luck: a grid
that judged every method fine would pass a broken method too.
usage: run_content_grid_small.py STEADYXR_EVAL OUT_DIR CONTENT_GRID_PY"""
import json
import os
import shutil
import subprocess
import sys

exe, out, grid = sys.argv[1], sys.argv[2], sys.argv[3]
shutil.rmtree(out, ignore_errors=True)
env = dict(os.environ)
env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":")  # as eval_run.py
res = subprocess.run([sys.executable, grid, "--eval", exe, "--out", out, "--methods", "none,taa,default",
                      "--rates", "30", "--ppd", "0", "--scenes", "fade,video", "--motions", "tremor-1x",
                      "--images", "zoneplate", "--seconds", "1", "--check", "default"],
                     capture_output=True, text=True, timeout=200, env=env)
print(res.stdout[-3000:])
print(res.stderr[-3000:], file=sys.stderr)
assert res.returncode == 0, f"content_grid.py exited {res.returncode}: the default breaks the promise here"

with open(os.path.join(out, "summary.json")) as f:
    summary = json.load(f)
default, taa = summary["default"], summary["taa"]
assert default["cases"] == 2 and taa["cases"] == 2, summary
assert default["above_none"] == 0 and not default["broken"], default
assert taa["above_none"] >= 1, f"taa should lag content that changes in place: {taa}"
assert taa["frame_misses"] - taa["frame_misses_lucky_none"] >= 1, f"taa's frame misses all called luck: {taa}"
assert len(taa["broken"]) >= 1, taa
print("ok")
