"""Held-out stress pictures for the image viewer (eval/stress.py): kinds the corpus does not hold.

Every picture is drawn from a seeded numpy Generator, so a (seed, case) pair always gives the same
PNG. Sizes and frequencies are in *screen pixels*: the image viewer's plane covers
PLANE_HEIGHT_FRACTION of the eye image's height (eval/pictures.cpp, kPlaneHeightFraction), and a
picture is made OVERSAMPLE texels per screen pixel, so that detail near and above the screen's
Nyquist frequency (0.5 cycles per pixel) exists in the texture; with mipmaps the sampler filters
it, with --no-mipmaps it aliases. Values are display-encoded (sRGB) 8-bit, as PNGs are.
"""

import numpy as np

# eval/pictures.cpp: the 1.2 m plane at 1.5 m over the eye's vertical tangent span 2.1452.
PLANE_HEIGHT_FRACTION = 1.2 / (1.5 * 2.1452)
# Texels per screen pixel: above-Nyquist content up to 2 cycles/px (the texture's own Nyquist).
OVERSAMPLE = 4


def picture_size(screen_height):
    """(width, height) in texels of a 4:3 picture (the plane's aspect) for this eye image height."""
    h = max(16, int(round(OVERSAMPLE * PLANE_HEIGHT_FRACTION * screen_height)))
    return h * 4 // 3, h


def _texel_grid(w, h):
    """Texel-centre coordinates in screen pixels (origin at the picture's centre)."""
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    return (xs + 0.5 - w / 2) / OVERSAMPLE, (ys + 0.5 - h / 2) / OVERSAMPLE


def _log_uniform(rng, lo, hi):
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def _to_rgb8(v):
    """Grey or RGB float picture in [0, 1] (display values) to uint8 RGB."""
    if v.ndim == 2:
        v = np.repeat(v[:, :, None], 3, axis=2)
    return np.clip(np.rint(v * 255.0), 0, 255).astype(np.uint8)


def powerlaw_noise(rng, w, h):
    """Random-phase noise whose power spectrum falls as 1/f^beta.

    beta in [0.5, 3]: natural images sit near 2 (Field 1987, JOSA A 4:2379; van der Schaaf and
    van Hateren 1996, Vision Res 36:2759, 1.88 +- 0.43); 0.5 is far more fine detail than a photo,
    3 far less. RMS contrast 0.05-0.25 about a mean of 0.2-0.8; half of them in colour."""
    beta = rng.uniform(0.5, 3.0)
    fy = np.fft.fftfreq(h)[:, None] * OVERSAMPLE  # cycles per screen pixel
    fx = np.fft.fftfreq(w)[None, :] * OVERSAMPLE
    f = np.hypot(fx, fy)
    f[0, 0] = np.inf  # no DC: the mean is set below
    amplitude = f ** (-beta / 2.0)
    channels = 3 if rng.uniform() < 0.5 else 1
    out = []
    for _ in range(channels):
        phase = rng.uniform(0, 2 * np.pi, size=(h, w))
        field = np.real(np.fft.ifft2(amplitude * np.exp(1j * phase)))
        out.append(field / field.std())
    field = np.stack(out, axis=2) if channels == 3 else out[0]
    v = rng.uniform(0.2, 0.8) + rng.uniform(0.05, 0.25) * field
    return _to_rgb8(v), {"beta": round(beta, 3), "colour": channels == 3}


def grating(rng, w, h):
    """A sine or square grating, or a zone plate, at a random angle and frequency near and above
    the screen's Nyquist frequency (0.5 cycles/px): 0.3-1.5 cycles/px (the texture holds up to 2)."""
    x, y = _texel_grid(w, h)
    mean, amp = rng.uniform(0.3, 0.7), rng.uniform(0.1, 0.3)
    if rng.uniform() < 0.35:
        # Zone plate: local frequency rises linearly from 0 at a random centre to f_max at radius r_max.
        cx, cy = rng.uniform(-0.3, 0.3) * w / OVERSAMPLE, rng.uniform(-0.3, 0.3) * h / OVERSAMPLE
        f_max = rng.uniform(0.5, 1.5)
        r_max = np.hypot(w, h) / OVERSAMPLE / 2
        r2 = (x - cx) ** 2 + (y - cy) ** 2
        v = mean + amp * np.cos(np.pi * f_max * r2 / r_max)
        return _to_rgb8(v), {"kind": "zoneplate", "f_max": round(f_max, 3)}
    f, angle = rng.uniform(0.3, 1.5), rng.uniform(0, np.pi)
    phase = 2 * np.pi * f * (x * np.cos(angle) + y * np.sin(angle)) + rng.uniform(0, 2 * np.pi)
    square = rng.uniform() < 0.5
    wave = np.sign(np.sin(phase)) if square else np.sin(phase)
    return _to_rgb8(mean + amp * wave), {
        "kind": "square" if square else "sine",
        "f": round(f, 3),
        "angle_deg": round(np.degrees(angle), 1),
    }


def _two_levels(rng):
    """Background and ink: usually any contrast, 30 % of them dark on dark (both below 0.15:
    where sRGB's steps are largest in linear light)."""
    if rng.uniform() < 0.3:
        return rng.uniform(0.0, 0.15), rng.uniform(0.0, 0.15)
    return rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)


def line_art(rng, w, h):
    """10-60 straight lines, each 0.3-3 px wide (log-uniform), drawn with exact area coverage."""
    x, y = _texel_grid(w, h)
    background, ink = _two_levels(rng)
    v = np.full((h, w), background)
    n = int(rng.integers(10, 61))
    half_w, half_h = w / OVERSAMPLE / 2, h / OVERSAMPLE / 2
    for _ in range(n):
        p0 = np.array([rng.uniform(-half_w, half_w), rng.uniform(-half_h, half_h)])
        p1 = np.array([rng.uniform(-half_w, half_w), rng.uniform(-half_h, half_h)])
        width = _log_uniform(rng, 0.3, 3.0)
        d = p1 - p0
        length2 = max(float(d @ d), 1e-9)
        t = np.clip(((x - p0[0]) * d[0] + (y - p0[1]) * d[1]) / length2, 0.0, 1.0)
        dist = np.hypot(x - (p0[0] + t * d[0]), y - (p0[1] + t * d[1]))
        # Coverage of a texel (1/OVERSAMPLE px wide) by a band of this width, linear ramp over a texel.
        cover = np.clip((width / 2 - dist) * OVERSAMPLE + 0.5, 0.0, 1.0)
        v = v * (1 - cover) + ink * cover
    return _to_rgb8(v), {"lines": n, "background": round(background, 3), "ink": round(ink, 3)}


def checkerboard(rng, w, h):
    """Squares of side 0.6-8 px (log-uniform: from above Nyquist to coarse), rotated 0-90 deg."""
    x, y = _texel_grid(w, h)
    side, angle = _log_uniform(rng, 0.6, 8.0), rng.uniform(0, np.pi / 2)
    u = (x * np.cos(angle) + y * np.sin(angle)) / side
    w_ = (-x * np.sin(angle) + y * np.cos(angle)) / side
    a, b = _two_levels(rng)
    odd = (np.floor(u) + np.floor(w_)) % 2 == 1
    return _to_rgb8(np.where(odd, a, b)), {"side_px": round(side, 3), "angle_deg": round(np.degrees(angle), 1)}


def dark_specks(rng, w, h):
    """High-dynamic-range-like: a dark scene (display 0-0.06, faint 1/f^2 texture) with bright
    specks (display 0.7-1, some coloured) of 0.2-3 px, 0.2-5 % of the area (stars, lamps, glints)."""
    x, y = _texel_grid(w, h)
    dark, _ = powerlaw_noise(rng, w, h)
    v = dark.astype(np.float64).mean(axis=2) / 255.0
    v = rng.uniform(0.0, 0.04) + 0.02 * (v - v.mean()) / max(v.std(), 1e-9)
    v = np.repeat(np.clip(v, 0, 1)[:, :, None], 3, axis=2)
    area = rng.uniform(0.002, 0.05) * (w * h) / OVERSAMPLE**2
    count = 0
    while area > 0 and count < 2000:
        r = _log_uniform(rng, 0.1, 1.5)  # radius: 0.2-3 px across
        cx, cy = rng.uniform(x.min(), x.max()), rng.uniform(y.min(), y.max())
        colour = np.full(3, rng.uniform(0.7, 1.0))
        if rng.uniform() < 0.3:
            colour = rng.uniform(0.3, 1.0, size=3)
        cover = np.clip((r - np.hypot(x - cx, y - cy)) * OVERSAMPLE + 0.5, 0.0, 1.0)[:, :, None]
        v = v * (1 - cover) + colour * cover
        area -= np.pi * r * r
        count += 1
    return _to_rgb8(v), {"specks": count}


def low_gradient(rng, w, h):
    """A smooth ramp of only 2-12 8-bit codes across the picture (banding: the PNG's own steps),
    at a random angle and level 0.02-0.9, half of them with a gentle radial bulge."""
    x, y = _texel_grid(w, h)
    codes, angle, level = rng.uniform(2, 12), rng.uniform(0, 2 * np.pi), rng.uniform(0.02, 0.9)
    span = np.hypot(w, h) / OVERSAMPLE
    ramp = (x * np.cos(angle) + y * np.sin(angle)) / span
    if rng.uniform() < 0.5:
        ramp = ramp + 0.5 * ((x**2 + y**2) / (span / 2) ** 2 - 0.5)
    return _to_rgb8(level + codes / 255.0 * ramp), {"codes": round(codes, 2), "level": round(level, 3)}


def text_blocks(rng, w, h):
    """Text-like blocks: lines of 'words' whose glyphs are random strokes on a 3x5 cell grid,
    glyph height 3-10 px (log-uniform: below a legible 5 px up to comfortable), any contrast."""
    paper, ink = _two_levels(rng)
    if abs(paper - ink) < 0.05:
        ink = 1.0 - paper
    v = np.full((h, w), paper)
    glyph_h = _log_uniform(rng, 3.0, 10.0) * OVERSAMPLE  # texels
    cell = glyph_h / 5.0
    stroke = max(1, int(round(cell)))
    y0 = rng.uniform(0, glyph_h)
    while y0 + glyph_h < h:
        x0 = rng.uniform(0, 2 * glyph_h)
        while x0 + 3 * cell < w:
            for _ in range(int(rng.integers(2, 9))):  # a word of 2-8 glyphs
                if x0 + 3 * cell >= w:
                    break
                for _ in range(int(rng.integers(2, 6))):  # strokes of the glyph
                    r, c = int(rng.integers(0, 5)), int(rng.integers(0, 3))
                    top, left = int(y0 + r * cell), int(x0 + c * cell)
                    if rng.uniform() < 0.5:  # horizontal stroke
                        v[top : top + stroke, left : int(x0 + 3 * cell)] = ink
                    else:  # vertical stroke
                        v[top : int(y0 + 5 * cell), left : left + stroke] = ink
                x0 += 4 * cell
            x0 += 3 * cell
        y0 += glyph_h * rng.uniform(1.3, 2.0)
    return _to_rgb8(v), {"glyph_px": round(glyph_h / OVERSAMPLE, 2), "paper": round(paper, 3), "ink": round(ink, 3)}


KINDS = {
    "noise": powerlaw_noise,
    "grating": grating,
    "lines": line_art,
    "checker": checkerboard,
    "specks": dark_specks,
    "gradient": low_gradient,
    "text": text_blocks,
}


def make_picture(kind, rng, screen_height):
    """(uint8 HxWx3 array, parameters drawn) of one picture of this kind for this eye image height."""
    w, h = picture_size(screen_height)
    return KINDS[kind](rng, w, h)
