#!/usr/bin/env python3
"""CI: `steadyxr-eval --app-msaa 4`, an app that renders with 4x MSAA and submits the resolved image.

Checked against the eval's own `msaa4` baseline, which renders the same MSAA image on its own path: with
--app-msaa 4, `none` (the app's image) is that image to the bit, in every frame, and so is `taa`'s first
frame (no history yet: the filter's output is its input, which is how the test sees that the filters read
the MSAA image); without it, the same frame of `none` and `taa` is the 1-sample render, which differs from
`msaa4` on the wires' edges. The default keeps the never-worse promise against the MSAA image. With
--app-msaa the eval reports each method's error on the resolved edges, the ring beside them and the rest
(resolved_edges.csv): the three sets partition both eyes' pixels and their pooled RMSE is the frame's; the
edges and the ring are where the left eye's two renders (written with --write-frames) differ and beside
them, both eyes about twice the left's; `none`'s error is largest on the edges. Bad values stop the run
with exit 2 and a message.
usage: run_app_msaa_small.py STEADYXR_EVAL OUT_DIR"""
import csv
import os
import shutil
import sys

import numpy as np
from PIL import Image

from eval_run import assert_refused, run_eval

exe, out = sys.argv[1], sys.argv[2]
shutil.rmtree(out, ignore_errors=True)


def run(folder, extra):
    run_eval([exe, "--out", folder, "--scenes", "thin", "--motions", "tremor-1x", "--methods",
              "none,taa,default,msaa4", "--resolution", "64", "--frames", "8", "--warp-steps", "0", "--no-sweeps",
              "--no-progress", "--write-frames", "1"] + extra, tail=1500)
    with open(os.path.join(folder, "timeseries.csv")) as f:
        frames = {(r["method"], int(r["frame"])): float(r["rmse"]) for r in csv.DictReader(f)}
    with open(os.path.join(folder, "results.csv")) as f:
        rows = {r["method"]: r for r in csv.DictReader(f)}
    return frames, rows


one, one_rows = run(os.path.join(out, "one_sample"), [])
msaa, msaa_rows = run(os.path.join(out, "app_msaa4"), ["--app-msaa", "4"])
print(f"frame 0 RMSE: 1 sample {one[('none', 0)]:.5f}, MSAA {msaa[('none', 0)]:.5f}")
assert one[("none", 0)] == one[("taa", 0)] != one[("msaa4", 0)], "without --app-msaa the app's image is 1 sample"
assert msaa[("none", 0)] == msaa[("taa", 0)] == msaa[("msaa4", 0)], "the filters did not take the MSAA image"
assert all(msaa[("none", f)] == msaa[("msaa4", f)] for f in range(8)), "none is not the MSAA image in every frame"
assert one[("msaa4", 0)] == msaa[("msaa4", 0)], "the msaa4 baseline changed with --app-msaa"
assert msaa_rows["none"]["samples"] == "4" and one_rows["none"]["samples"] == "1", "the samples column"
default, none = float(msaa_rows["default"]["rmse"]), float(msaa_rows["none"]["rmse"])
print(f"with the app's 4x MSAA: default / none {default / none:.3f}")
assert default <= none, "the default is above the app's MSAA image"
assert max(msaa[("default", f)] / msaa[("none", f)] for f in range(8)) <= 1.10, "a frame above 1.10x none's"

# Resolved edges: none without --app-msaa; with it, every method and frame, the sets a partition.
assert not os.path.exists(os.path.join(out, "one_sample", "resolved_edges.csv")), "resolved_edges.csv, 1 sample"
with open(os.path.join(out, "app_msaa4", "resolved_edges.csv")) as f:
    edges = {(r["method"], int(r["frame"])): r for r in csv.DictReader(f)}
assert set(edges) == set(msaa), "resolved_edges.csv lacks a method's frame"
for (method, frame), r in edges.items():
    counts = [int(r[part + "_pixels"]) for part in ("edge", "ring", "rest")]
    assert sum(counts) == 2 * 64 * 64, f"the sets do not partition both eyes: {counts}"
    pooled = sum(n * max(float(r["rmse_" + part]), 0.0) ** 2 for n, part in zip(counts, ("edge", "ring", "rest")))
    assert abs((pooled / sum(counts)) ** 0.5 - msaa[(method, frame)]) <= 2e-6, "the sets' RMSE is not the frame's"


def left_eye(folder, frame):
    frames = os.path.join(folder, "frames")
    return np.asarray(Image.open(os.path.join(frames, os.listdir(frames)[0], f"none_{frame}.png")).convert("RGB"))


for frame in (0, 7):
    a, b = left_eye(os.path.join(out, "one_sample"), frame), left_eye(os.path.join(out, "app_msaa4"), frame)
    edge = (a != b).any(axis=2)
    beside = np.zeros_like(edge)
    beside[1:] |= edge[:-1]
    beside[:-1] |= edge[1:]
    beside[:, 1:] |= edge[:, :-1]
    beside[:, :-1] |= edge[:, 1:]
    left = {"edge": int(edge.sum()), "ring": int((beside & ~edge).sum())}
    r = edges[("none", frame)]
    print(f"frame {frame}: left eye's edges {left['edge']} ring {left['ring']}; both eyes' {r['edge_pixels']} "
          f"{r['ring_pixels']}")
    for part in ("edge", "ring"):
        both = int(r[part + "_pixels"])
        assert left[part] > 0 and abs(both - 2 * left[part]) <= 0.15 * 2 * left[part], f"the {part} set's pixels"
none0 = [float(edges[("none", 0)]["rmse_" + part]) for part in ("edge", "ring", "rest")]
assert none0[0] > none0[1] > none0[2], f"none's error is not largest where MSAA resolved edges: {none0}"

assert_refused(exe, os.path.join(out, "bad"), ["--app-msaa", "3"], "bad value for --app-msaa")
assert_refused(exe, os.path.join(out, "bad"), ["--app-msaa", "4", "--render-sizes", "1,0.9"],
               "leave out --ppd, --cant and --app-msaa")
print("--app-msaa: the app's MSAA image is the filters' input and none")
