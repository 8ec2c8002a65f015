#!/usr/bin/env python3
"""Round 26: what one frame says about the footprint's k (docs/method-history.md, "Round 26").

Reads the frames `steadyxr-eval --write-frames N` wrote (left eye, 8-bit sRGB PNGs: the truth gt_F.png and
none_F.png, the unfiltered render) and prints per case, averaged over the frames written:
- the one-frame footprint alone (item 4's [k, 1 - 2k, k] per axis on the square roots of linear light,
  squared back) at k = 0, 1/24, 1/16, 1/12, 1/8: its RMSE against the truth, relative to none's (k = 0);
- the truth's own least-squares k: the k that makes c + k (c_W + c_E + c_N + c_S - 4c) closest to the truth in
  linear luma over the frame (what a frame-wide k could be at best, one frame at a time);
- a self-similar estimate the layer could make without the truth: the same least squares one scale up,
  the 3x3 box mean of the render standing for the truth and the stencil at a stride of 3 px.

    build/eval/steadyxr-eval --corpus --methods none --motions tremor-1x,sway --write-frames 8 --out /tmp/k
    python3 docs/experiments/round26-footprint-k.py /tmp/k/frames
"""
import glob
import os
import sys

import numpy as np
from PIL import Image

KS = [0.0, 1 / 24, 1 / 16, 1 / 12, 1 / 8]


def decode(codes):  # IEC 61966-2-1
    c = codes / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def encode(linear):
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, x * 12.92, 1.055 * x ** (1 / 2.4) - 0.055) * 255.0


def load(path):
    return np.asarray(Image.open(path).convert("RGB")).astype(np.float64)


def footprint(codes, k):
    """Item 4 from its definition: the separable [k, 1 - 2k, k] filter on square roots, squared back."""
    roots = np.sqrt(decode(codes))
    weights = (k, 1.0 - 2.0 * k, k)
    padded = np.pad(roots, ((1, 1), (1, 1), (0, 0)), mode="edge")
    rows = sum(w * padded[i:i + roots.shape[0], :, :] for i, w in enumerate(weights))
    return encode(sum(w * rows[:, i:i + roots.shape[1], :] for i, w in enumerate(weights)) ** 2)


def luma(codes):
    lin = decode(codes)
    return 0.25 * lin[..., 0] + 0.5 * lin[..., 1] + 0.25 * lin[..., 2]


def least_squares_k(target, centre, laplacian):
    return float(((target - centre) * laplacian).sum() / max((laplacian * laplacian).sum(), 1e-12))


def stencil(img, s):
    """The 5-point stencil at stride s, and the centres it belongs to."""
    c = img[s:-s, s:-s]
    return img[:-2 * s, s:-s] + img[2 * s:, s:-s] + img[s:-s, :-2 * s] + img[s:-s, 2 * s:] - 4.0 * c, c


def truth_k(render, truth):
    lap, centre = stencil(render, 1)
    return least_squares_k(truth[1:-1, 1:-1], centre, lap)


def self_similar_k(render, s=3):
    h, w = render.shape
    box = np.lib.stride_tricks.sliding_window_view(render, (s, s)).mean(axis=(2, 3))  # box[y, x] centred at +s//2
    lap, centre = stencil(render, s)
    r = s // 2
    return least_squares_k(box[s - r:h - s - r, s - r:w - s - r], centre, lap)


def main(root):
    print("case                                     one frame's footprint / none's at k = 0, 1/24, 1/16, 1/12, 1/8"
          "   truth's k   self-similar k")
    for case in sorted(glob.glob(os.path.join(root, "*"))):
        frames = sorted(int(p.rsplit("_", 1)[1][:-4]) for p in glob.glob(os.path.join(case, "none_*.png")))
        errors, tk, sk = [], [], []
        for f in frames:
            render, truth = load(f"{case}/none_{f}.png"), load(f"{case}/gt_{f}.png")
            errors.append([np.sqrt(((footprint(render, k) - truth) ** 2).mean()) for k in KS])
            tk.append(truth_k(luma(render), luma(truth)))
            sk.append(self_similar_k(luma(render)))
        e = np.mean(errors, axis=0)
        print(f"{os.path.basename(case):40s} " + " ".join(f"{x / e[0]:.3f}" for x in e) +
              f"   1/{1 / np.mean(tk):5.1f}     1/{1 / np.mean(sk):5.1f}")


if __name__ == "__main__":
    main(sys.argv[1])
