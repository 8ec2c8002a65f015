#!/usr/bin/env python3
"""Round 29, an experiment (not in the layer): could the layer tell a frame its pose does not explain?

Under artificial locomotion (eval/locomotion.h) the picture moves while the submitted head pose does not. A frame
whose history, reprojected with the pose, differs from the input by more than the input's own adjacent pixels differ
from each other is misplaced by about a pixel or more everywhere. Per frame: R = mean |Y_t - Y_t-1| (linear luma,
no reprojection: for a still head an upper bound on the probe's residual), D = the input's mean |difference| between
adjacent pixels (horizontal and vertical averaged); prints R/D for a still head (tremor, microsaccades) and at the
frames where a rig motion starts or is held.

    for L in none snap:30 turn:30 strafe:1; do
      build/eval/steadyxr-eval --out /tmp/proto/$L --corpus --scenes imageviewer \\
        --motions tremor-0.5x,tremor-1x,tremor-2x,microsaccades --methods none --write-frames 1 --locomotion $L
    done
    python3 docs/experiments/round29-cut-statistic.py /tmp/proto

The corpus's runs have 48 frames: a stick is pressed at frame 12 (first moved frame 13) and released at 36; a snap
turns at 16 and back at 32.
"""
import glob
import os
import sys

import numpy as np
from PIL import Image


def luma(path):
    srgb = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0
    lin = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)  # the passes work in linear light
    return 0.25 * lin[..., 0] + 0.5 * lin[..., 1] + 0.25 * lin[..., 2]


def ratios(folder):
    """Per case, R/D for frames 1..n-1 (index k-1 holds frame k)."""
    out = {}
    for case in sorted(os.listdir(folder)):
        n = len(glob.glob(f"{folder}/{case}/none_*.png"))
        frames = [luma(f"{folder}/{case}/none_{k}.png") for k in range(n)]
        out[case] = []
        for k in range(1, n):
            residual = np.mean(np.abs(frames[k] - frames[k - 1]))
            y = frames[k]
            detail = 0.5 * (np.mean(np.abs(y[:, 1:] - y[:, :-1])) + np.mean(np.abs(y[1:, :] - y[:-1, :])))
            out[case].append(residual / max(detail, 1e-9))
    return out


root = sys.argv[1]
still = [r for rs in ratios(f"{root}/none/frames").values() for r in rs]
print(f"still head: {len(still)} frames, R/D median {np.median(still):.3f}, 99th percentile "
      f"{np.percentile(still, 99):.3f}, max {max(still):.3f}")
for spec, frames in (("snap:30", (16, 32)), ("turn:30", (13,)), ("strafe:1", (13,))):
    per_case = ratios(f"{root}/{spec}/frames")
    for k in frames:
        v = [rs[k - 1] for rs in per_case.values()]
        print(f"{spec} frame {k}: R/D min {min(v):.3f}, median {np.median(v):.3f}, max {max(v):.3f}")
    if spec != "snap:30":
        held = [rs[k - 1] for rs in per_case.values() for k in range(14, 36)]
        print(f"{spec} frames 14-35 (the stick held): R/D min {min(held):.3f}, median {np.median(held):.3f}, "
              f"max {max(held):.3f}")
