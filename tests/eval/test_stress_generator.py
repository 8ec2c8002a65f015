#!/usr/bin/env python3
"""CI: eval/stress.py's generator draws what its docstrings say (no GPU).

Each check is written from the definition of the stressor, not from the generator's code:
determinism; a trace's angular velocity integrates to its own orientations (as imu::loadTrace
integrates wx,wy,wz); tremor power lies in the 8-12 Hz band at the drawn RMS; a microsaccade
moves the head by its drawn size; a turn peaks at its drawn speed; power-law noise has the drawn
spectral slope; a sine grating has the drawn frequency in cycles per screen pixel; a nod or shake
oscillates at its drawn frequency and size about its own axis; a dodge moves the eyes by its drawn amount
and back.
usage: test_stress_generator.py EVAL_DIR"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, sys.argv[1])
import stress_motion as sm  # noqa: E402
import stress_pictures as sp  # noqa: E402


def rng(i):
    return np.random.default_rng([7, i])


def quat_mul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.array([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw])


def integrate_omega(rows):
    """Orientation from the head-frame angular velocity, trapezoidal (imu/src/motion.cpp loadTrace)."""
    q = rows[0, 1:5].copy()
    out = [q]
    for i in range(1, len(rows)):
        w = 0.5 * (rows[i - 1, 5:8] + rows[i, 5:8]) * (rows[i, 0] - rows[i - 1, 0])
        angle = np.linalg.norm(w)
        dq = np.array([1.0, 0, 0, 0])
        if angle > 0:
            dq = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * w / angle])
        q = quat_mul(q, dq)
        q /= np.linalg.norm(q)
        out.append(q)
    return np.array(out)


def angle_between_deg(q1, q2):
    return np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(q1 * q2, axis=-1)), 0, 1)))


# 1. Determinism: the same (seed, index) gives the same picture and trace, another index does not.
for kind in sp.KINDS:
    a, _ = sp.make_picture(kind, rng(1), 96)
    b, _ = sp.make_picture(kind, rng(1), 96)
    c, _ = sp.make_picture(kind, rng(2), 96)
    assert a.shape == (sp.picture_size(96)[1], sp.picture_size(96)[0], 3) and a.dtype == np.uint8, kind
    assert np.array_equal(a, b) and not np.array_equal(a, c), kind
for kind in sm.KINDS + sm.OPT_IN_KINDS:
    a, pa = sm.make_trace(kind, rng(3), 1.2)
    b, pb = sm.make_trace(kind, rng(3), 1.2)
    assert np.array_equal(a, b) and pa == pb, kind
    assert np.allclose(np.linalg.norm(a[:, 1:5], axis=1), 1.0, atol=1e-9), kind
    assert np.allclose(np.diff(a[:, 0]), 1.0 / sm.RATE_HZ) and a[-1, 0] >= 1.2 + 0.49, kind
    # 2. wx,wy,wz are the head-frame rates of the written orientations: integrating them (as the
    #    eval does for a trace without quaternions) stays on the quaternions.
    drift_deg = angle_between_deg(integrate_omega(a), a[:, 1:5]).max()
    assert drift_deg < 0.01, f"{kind}: angular velocity integrates {drift_deg:.4f} deg away from the orientations"
    # The eyes turn about the neck pivot: at identity orientation they are at the origin.
    assert np.linalg.norm(a[0, 8:11]) < 0.05, kind

# 3. Tremor alone: its power in the 8-12 Hz band, at the drawn RMS per axis (small angles: the
#    rotation vector's components are the per-axis angles).
rows, p = sm.make_trace("tremor", rng(4), 4.0)
angles = np.degrees(2 * rows[:, 2:5] * np.sign(rows[:, 1:2]))
for axis in range(3):
    x = angles[:, axis] - angles[:, axis].mean()
    assert abs(x.std() / p["tremor_rms_deg"] - 1) < 0.02, (axis, x.std(), p)
    power = np.abs(np.fft.rfft(x)) ** 2
    f = np.fft.rfftfreq(len(x), 1 / sm.RATE_HZ)
    assert power[(f >= 8) & (f <= 12)].sum() > 0.99 * power.sum(), axis

# 4. A microsaccade moves the head by its drawn size (tremor aside: compare the mean pose well
#    before and well after the jump), and lasts about its main-sequence duration.
for i in range(5, 9):
    rows, p = sm.make_trace("saccade", rng(i), 1.6)
    t0 = p["saccade_s"]
    before = rows[(rows[:, 0] > t0 - 0.2) & (rows[:, 0] < t0), 1:5].mean(axis=0)
    after = rows[(rows[:, 0] > t0 + 0.1) & (rows[:, 0] < t0 + 0.3), 1:5].mean(axis=0)
    jump = angle_between_deg(before / np.linalg.norm(before), after / np.linalg.norm(after))
    assert abs(jump - p["saccade_deg"]) < 0.05 * p["saccade_deg"] + 3 * p["tremor_rms_deg"] / np.sqrt(50), (jump, p)

# 5. A turn reaches its drawn peak speed (the eval's head speed is |w|), tremor aside.
for i in range(9, 12):
    rows, p = sm.make_trace("turn", rng(i), 2.0)
    peak = np.degrees(np.linalg.norm(rows[:, 5:8], axis=1)).max()
    # Tremor adds up to a few times its RMS angular speed (2 pi 12 Hz x RMS per axis).
    tremor_speed = 10 * p["tremor_rms_deg"] * 2 * np.pi * 12
    assert abs(peak - p["turn_peak_deg_s"]) < 0.03 * p["turn_peak_deg_s"] + tremor_speed, (peak, p)

# 6. Power-law noise: the radially averaged power spectrum falls with the drawn slope -beta.
for i in range(12, 18):
    pixels, p = sp.make_picture("noise", rng(i), 128)
    v = pixels.astype(np.float64).mean(axis=2)
    h, w = v.shape
    power = np.abs(np.fft.fft2(v - v.mean())) ** 2
    f = np.hypot(np.fft.fftfreq(h)[:, None] * sp.OVERSAMPLE, np.fft.fftfreq(w)[None, :] * sp.OVERSAMPLE)
    # Fit over the band between a few cycles per picture and below the 8-bit rounding floor.
    band = (f > 8 * sp.OVERSAMPLE / min(w, h)) & (f < 0.5)
    slope = np.polyfit(np.log(f[band]), np.log(power[band]), 1)[0]
    assert abs(-slope - p["beta"]) < 0.25, (slope, p)

# 7. A sine grating: its strongest frequency, in cycles per screen pixel, is the drawn one.
found = 0
for i in range(18, 60):
    pixels, p = sp.make_picture("grating", rng(i), 128)
    if p["kind"] != "sine":
        continue
    v = pixels.astype(np.float64).mean(axis=2)
    h, w = v.shape
    power = np.abs(np.fft.fft2(v - v.mean()))
    ky, kx = np.unravel_index(np.argmax(power), power.shape)
    fy, fx = np.fft.fftfreq(h)[ky] * sp.OVERSAMPLE, np.fft.fftfreq(w)[kx] * sp.OVERSAMPLE
    assert abs(np.hypot(fx, fy) - p["f"]) < 1.5 * sp.OVERSAMPLE / min(w, h), (np.hypot(fx, fy), p)
    found += 1
assert found >= 3, "too few sine gratings drawn to check"

# 8. --pictures: the kinds take turns among those named (in KINDS's order), every other draw as without it;
#    without it every kind takes its turn, so earlier seeds draw what they drew.
import contextlib  # noqa: E402
import io  # noqa: E402

import stress  # noqa: E402


def expect_refused(flags, message):
    """stress.py's arguments with these flags stop with exit status 2 and this message."""
    with contextlib.redirect_stderr(io.StringIO()) as err:
        try:
            stress.parse_args(["--eval", "x", "--out", "y"] + flags)
            raise AssertionError(f"{flags} accepted")
        except SystemExit as e:
            assert e.code == 2
    assert message in err.getvalue(), err.getvalue()


every, some = stress.parse_args(["--eval", "x", "--out", "y"]), stress.parse_args(
    ["--eval", "x", "--out", "y", "--pictures", "text,lines"])
drawn = [stress.draw_case(61, i, every)["picture_kind"] for i in range(len(sp.KINDS))]
assert sorted(drawn) == sorted(sp.KINDS) and drawn[0] == list(sp.KINDS)[61 % len(sp.KINDS)], drawn
named = [stress.draw_case(61, i, some) for i in range(6)]
assert [c["picture_kind"] for c in named] == ["text", "lines"] * 3, named  # KINDS has lines before text; 61 is odd
plain = stress.draw_case(61, 4, every)
assert {k: v for k, v in named[4].items() if k not in ("picture_kind", "rng")} == \
    {k: v for k, v in plain.items() if k not in ("picture_kind", "rng")}
expect_refused(["--pictures", "lines,photos"], "unknown kind(s) photos")
expect_refused(["--scenes", "imageviewer,depth"], "unknown scene(s) depth")  # round 44: each case's eval failed
expect_refused(["--cant", "10,25"], "--cant: '10,25' is not a list of angles in (0, 20] degrees")  # the eval's range
expect_refused(["--cant", "ten"], "--cant: 'ten' is not a list of angles")
def with_and_without(seed, index, flags, key, off):
    """Case `index` drawn with `flags` and without: the same case but for `key` (`off` without the flags)."""
    with_it, without = stress.draw_case(seed, index, flags), stress.draw_case(seed, index, every)
    assert without[key] == off, without
    assert {k: v for k, v in with_it.items() if k not in (key, "rng")} == \
        {k: v for k, v in without.items() if k not in (key, "rng")}, index
    return with_it


# --locomotion-fraction: every drawn rig motion is one the eval reads, within a game's settings, and
# it changes nothing else of a case (earlier seeds draw what they drew); a walk ahead stops 0.5 m short
# of the picture at 1.5 m over the half of the run the stick is held (eval/locomotion.h).
moving = stress.parse_args(["--eval", "x", "--out", "y", "--locomotion-fraction", "1"])
limits = {"turn": (20.0, 120.0), "snap": (20.0, 45.0), "strafe": (0.5, 3.0), "forward": (0.0, 3.0)}
kinds = set()
for i in range(40):
    with_rig = with_and_without(61, i, moving, "locomotion", "")
    kind, amount = with_rig["locomotion"].split(":")
    kinds.add(kind)
    low, high = limits[kind]
    assert low * 0.999 <= abs(float(amount)) <= high * 1.001, with_rig["locomotion"]
    if kind == "forward":
        assert float(amount) > 0 and float(amount) * with_rig["frames"] / with_rig["app_hz"] / 2 <= 1.0 + 1e-3, \
            with_rig
assert kinds == set(limits), kinds
# --drop-fraction: P within DROP_RANGE, a share of the cases near the fraction, the rest of a case as drawn
# without it, and the eval told it.
dropping = stress.parse_args(["--eval", "x", "--out", "y", "--drop-fraction", "0.5"])
drops = []
for i in range(40):
    with_drops = with_and_without(62, i, dropping, "drop", 0.0)
    command = stress.eval_command(dict(with_drops, trace="t.csv", picture="p.png"), dropping, Path("out"))
    if with_drops["drop"] > 0:
        assert stress.DROP_RANGE[0] <= with_drops["drop"] <= stress.DROP_RANGE[1], with_drops["drop"]
        assert command[command.index("--drop-frames") + 1] == f"{with_drops['drop']:g}", command
        drops.append(with_drops["drop"])
    else:
        assert "--drop-frames" not in command, command
assert 10 <= len(drops) <= 30, len(drops)  # 20 expected; about 3 standard deviations either side
# --cant-fraction: canted views at an angle from --cant, the eval told it, the rest of a case as drawn without it;
# a share of the cases near the fraction, at every --ppd.
canting = stress.parse_args(["--eval", "x", "--out", "y", "--cant-fraction", "0.5", "--cant", "5,10"])
canted = set()
for i in range(40):
    with_cant = with_and_without(63, i, canting, "cant", 0.0)
    command = stress.eval_command(dict(with_cant, trace="t.csv", picture="p.png"), canting, Path("out"))
    if with_cant["cant"] > 0:
        assert with_cant["cant"] in (5.0, 10.0), with_cant["cant"]
        assert command[command.index("--cant") + 1] == f"{with_cant['cant']:g}", command
        canted.add(i)
    else:
        assert "--cant" not in command, command
assert 10 <= len(canted) <= 30, len(canted)  # 20 expected; about 3 standard deviations either side
assert {stress.draw_case(63, i, canting)["ppd"] for i in canted} == set(stress.PPD_CHOICES)
# --msaa-fraction: the app's 4x MSAA, the eval told it, the rest of a case as drawn without it; a share of the
# cases near the fraction.
multisampling = stress.parse_args(["--eval", "x", "--out", "y", "--msaa-fraction", "0.5"])
multisampled = 0
for i in range(40):
    with_msaa = with_and_without(64, i, multisampling, "app_msaa", 1)
    command = stress.eval_command(dict(with_msaa, trace="t.csv", picture="p.png"), multisampling, Path("out"))
    if with_msaa["app_msaa"] > 1:
        assert with_msaa["app_msaa"] == 4, with_msaa["app_msaa"]
        assert command[command.index("--app-msaa") + 1] == "4", command
        multisampled += 1
    else:
        assert "--app-msaa" not in command, command
assert 10 <= multisampled <= 30, multisampled  # 20 expected; about 3 standard deviations either side

# 9. Round 40's opt-in kinds. A nod or shake: the angle about its axis (small angles: the rotation vector's
#    component), tremor filtered out below 6 Hz, rests before and after its window, has its strongest frequency
#    at the drawn one and a peak to peak of at most the drawn size and more than half of it (sin^2 envelope);
#    the other axis stays at tremor's size.
def lowpass(x, hz):
    spectrum = np.fft.rfft(x)
    spectrum[np.fft.rfftfreq(len(x), 1 / sm.RATE_HZ) > hz] = 0.0
    return np.fft.irfft(spectrum, len(x))


seen = set()
for i in range(60, 72):
    rows, p = sm.make_trace("gesture", rng(i), 2.4)
    seen.add(p["gesture"])
    axis = 0 if p["gesture"] == "nod" else 1
    angles = np.degrees(2 * rows[:, 2:5] * np.sign(rows[:, 1:2]))
    slow = lowpass(angles[:, axis] - angles[:, axis].mean(), 6.0)
    t = rows[:, 0]
    inside = (t >= p["gesture_s"]) & (t <= p["gesture_end_s"])
    rest = slow[(t < p["gesture_s"] - 0.05) | ((t > p["gesture_end_s"] + 0.05) & (t < 2.4))]
    assert np.ptp(rest) < 0.05 * p["gesture_pp_deg"], (np.ptp(rest), p)
    window = slow[inside] - slow[inside].mean()
    padded = np.zeros(8 * len(window))
    padded[: len(window)] = window
    f = np.fft.rfftfreq(len(padded), 1 / sm.RATE_HZ)
    strongest = f[np.argmax(np.abs(np.fft.rfft(padded)))]
    assert abs(strongest - p["gesture_hz"]) < 1.0 / (p["gesture_end_s"] - p["gesture_s"]), (strongest, p)
    assert 0.5 * p["gesture_pp_deg"] < np.ptp(slow[inside]) <= 1.01 * p["gesture_pp_deg"], (np.ptp(slow[inside]), p)
    other = lowpass(angles[:, 1 - axis] - angles[:, 1 - axis].mean(), 6.0)
    assert np.ptp(other) < 0.05 * p["gesture_pp_deg"], (np.ptp(other), p)
assert seen == {"nod", "shake"}, seen
#    A dodge or duck moves the eyes by the drawn amount along its axis (x sideways, y down) and back, at
#    about the drawn peak speed; the neck model's share of the tremor is millimetres.
seen = set()
for i in range(72, 84):
    rows, p = sm.make_trace("dodge", rng(i), 3.0)  # long enough to hold the whole dodge
    seen.add(p["dodge"])
    along = rows[:, 8] if p["dodge"] == "side" else -rows[:, 9]
    peak = along[np.argmax(np.abs(along))]
    assert abs(peak - p["dodge_cm"] / 100) < 0.005, (peak, p)
    assert abs(along[-1]) < 0.005 and abs(along[0]) < 0.005, (along[0], along[-1], p)
    speed = np.abs(np.gradient(along, 1 / sm.RATE_HZ)).max()
    assert abs(speed - p["dodge_peak_m_s"]) < 0.05 * p["dodge_peak_m_s"] + 0.05, (speed, p)
assert seen == {"side", "duck"}, seen
# 10. --motions: the kinds take turns among those named, the opt-in ones only when named; without it the
#     default kinds take their turns as before (earlier seeds draw what they drew).
default_kinds = [stress.draw_case(61, i, every)["motion_kind"] for i in range(40)]
assert set(default_kinds) == set(sm.KINDS), default_kinds
named = stress.parse_args(["--eval", "x", "--out", "y", "--motions", ",".join(sm.KINDS)])
assert [stress.draw_case(61, i, named)["motion_kind"] for i in range(40)] == default_kinds
opted = stress.parse_args(["--eval", "x", "--out", "y", "--motions", "dodge,gesture"])
drawn = [stress.draw_case(61, i, opted) for i in range(8)]
assert set(c["motion_kind"] for c in drawn) == set(sm.OPT_IN_KINDS), drawn
assert {k: v for k, v in drawn[3].items() if k not in ("motion_kind", "rng")} == \
    {k: v for k, v in stress.draw_case(61, 3, every).items() if k not in ("motion_kind", "rng")}
expect_refused(["--motions", "nod"], "unknown kind(s) nod")
print("stress generator OK")
