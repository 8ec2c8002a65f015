#!/usr/bin/env python3
"""Round 47's study (not built): can a frame's colours alone say that the app resolved MSAA into it?

Along rows and columns of `none`'s written frames (the app's own image, 8-bit), count strong steps
between flat sides: abrupt ones (a a | c c) and ones through a single pixel strictly between the sides
(a a m c c), as a resolved geometric edge leaves. R = resolved / (resolved + abrupt), per frame; a
1-sample render's geometric edges give R near 0, a 4x MSAA render's about 3/4 (a pixel is covered in part
unless the edge falls outside its samples' span). Texture steps count too: that is the question.

  build/eval/steadyxr-eval --corpus --methods none --write-frames 12 --out ONE
  build/eval/steadyxr-eval --corpus --app-msaa 4 --methods none --write-frames 12 --out MSAA
  python3 docs/experiments/round47-step-statistic.py ONE MSAA

Prints, per scene or picture, the range of the frames' R under each app and whether one threshold
separates them. T (a strong step) and t (a flat side) are in codes of luma, chosen before the run.

--depth-edges: only steps across a depth edge, from the app's depth buffer written beside each frame as
depth_N.f32 (the left eye's, float, row-major; the eval does not write it: round 47 used a one-off patch
that writes ft.depth[0] at --write-frames' frames).
"""
import glob
import math
import os
import sys
from collections import defaultdict

import numpy as np
from PIL import Image

STRONG_STEP_CODES, FLAT_CODES = 24.0, 3.0


# A depth edge: the depth buffer's value is affine in screen space on a plane (as 1/z is), so its second
# difference over three pixels is 0 on one surface up to float rounding; above this, two surfaces meet.
DEPTH_EDGE = 1e-5


def step_counts(rgb, depth=None):
    """(resolved, abrupt) strong steps; with depth (the app's depth buffer, same size), only those whose
    span holds a depth edge"""
    y = rgb.astype(np.float64) @ np.array([0.299, 0.587, 0.114])
    resolved = abrupt = 0
    for lines, dl in ((y, depth), (y.T, None if depth is None else depth.T)):
        a, b, c, d = lines[:, :-3], lines[:, 1:-2], lines[:, 2:-1], lines[:, 3:]
        is_abrupt = (np.abs(c - b) >= STRONG_STEP_CODES) & (np.abs(b - a) <= FLAT_CODES) & (np.abs(d - c) <= FLAT_CODES)
        if dl is not None:
            d2 = np.abs(dl[:, :-2] - 2 * dl[:, 1:-1] + dl[:, 2:]) > DEPTH_EDGE  # centred on pixel 1..n-2
            is_abrupt &= d2[:, :-1] | d2[:, 1:]  # over (a, b, c) or (b, c, d)
        abrupt += int(is_abrupt.sum())
        a, b, m, c, d = lines[:, :-4], lines[:, 1:-3], lines[:, 2:-2], lines[:, 3:-1], lines[:, 4:]
        low, high = np.minimum(b, c), np.maximum(b, c)
        is_resolved = ((np.abs(c - b) >= STRONG_STEP_CODES) & (np.abs(b - a) <= FLAT_CODES) &
                       (np.abs(d - c) <= FLAT_CODES) & (m > low + FLAT_CODES) & (m < high - FLAT_CODES))
        if dl is not None:
            d2 = np.abs(dl[:, :-2] - 2 * dl[:, 1:-1] + dl[:, 2:]) > DEPTH_EDGE
            is_resolved &= d2[:, :-2] | d2[:, 1:-1] | d2[:, 2:]  # over (a, b, m), (b, m, c) or (m, c, d)
        resolved += int(is_resolved.sum())
    return resolved, abrupt


def frame_ratios(root, with_depth):
    """{case: [R per written frame with at least one strong step]}"""
    out = {}
    for case in sorted(glob.glob(os.path.join(root, "frames", "*"))):
        rs = []
        for png in sorted(glob.glob(os.path.join(case, "none_*.png"))):
            rgb = np.asarray(Image.open(png).convert("RGB"))
            depth = None
            if with_depth:
                path = png.replace("none_", "depth_").replace(".png", ".f32")
                if not os.path.exists(path):
                    continue
                depth = np.fromfile(path, dtype=np.float32).astype(np.float64).reshape(rgb.shape[:2])
            r, a = step_counts(rgb, depth)
            if r + a > 0:
                rs.append(r / (r + a))
        out[os.path.basename(case)] = rs
    return out


def group_of(case):
    parts = case.split("-")
    if case.endswith("nodepth"):
        return parts[0] + "/nodepth"
    return parts[0] + ("/" + parts[-1] if parts[0] == "imageviewer" else "")


def main(one_dir, msaa_dir, with_depth):
    one, msaa = frame_ratios(one_dir, with_depth), frame_ratios(msaa_dir, with_depth)
    groups = defaultdict(lambda: ([], []))
    for case in one:
        if not one[case] or not msaa.get(case):
            continue
        groups[group_of(case)][0].extend(one[case])
        groups[group_of(case)][1].extend(msaa.get(case, []))
    print(f"{'scene/picture':24s} {'1 sample: R range (median)':>28s} {'4x MSAA: R range (median)':>28s}  separable")
    all_one, all_msaa = [], []
    for g, (a, b) in sorted(groups.items()):
        all_one += a
        all_msaa += b
        sep = "yes" if a and b and max(a) < min(b) else "no"
        print(f"{g:24s} {min(a):10.2f}-{max(a):.2f} ({np.median(a):.2f})      {min(b):10.2f}-{max(b):.2f} ({np.median(b):.2f})"
              f"       {sep}")
    best = max(((sum(r < th for r in all_one) + sum(r >= th for r in all_msaa)) / (len(all_one) + len(all_msaa)), th)
               for th in np.linspace(0, 1, 101))
    print(f"one threshold over every frame: at R = {best[1]:.2f}, {100 * best[0]:.1f} % of "
          f"{len(all_one) + len(all_msaa)} frames classified right")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], "--depth-edges" in sys.argv[3:])
