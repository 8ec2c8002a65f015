"""Held-out head-motion traces for eval/stress.py, drawn from a physiological parameter space.

A trace is written in the format imu::loadTrace reads (imu/src/motion.cpp):
  t_s,qw,qx,qy,qz,wx,wy,wz,px,py,pz
at 1 kHz (the IMU's rate, steadyxr-imu-emu --rate default), wx,wy,wz the angular velocity in the
head frame (rad/s; the eval's head speed comes from it), p the eyes' centre in metres. Axes as the
presets (imu/src/motion_presets.cpp): x right (pitch), y up (yaw), z back (roll); the head turns
about a neck pivot 7 cm below and behind the eyes (imu/motion_extra.h, kNeckToEyes*), so every
rotation also translates the eyes.

Ranges and where they come from (each component's docstring says more):
  tremor   8-12 Hz band (physiological tremor: Elble and Koller 1990, "Tremor"; McAuley and
           Marsden 2000, Brain 123:1545), RMS per axis log-uniform 0.005-0.5 deg: the corpus's
           0.01-0.04 deg in the middle, 25x its 1x above (essential head tremor reaches degrees).
  drift    0.02-0.5 deg/s, direction wandering (fixational drift of the head; presets: 0.1 deg/s).
  sway     0.1-1 Hz, 0.5-6 deg yaw, 0.2-3 deg pitch, 0.5-3 cm side, peak to peak (quiet stance:
           Winter 1995, Gait & Posture 3:193; most power below 0.5 Hz).
  pursuit  3-60 deg/s (log-uniform), ramp in 0.1-0.3 s, stop in 0.05-0.15 s, then hold (slow head
           pursuit; presets 15-30 deg/s).
  saccade  one jump of 0.05-1 deg (microsaccades are below 1 deg: Martinez-Conde et al. 2004,
           Nat Rev Neurosci 5:229), duration 21 + 2.2 ms/deg (the saccadic main sequence,
           Carpenter 1988, "Movements of the Eyes"), minimum-jerk profile, at a random time.
  turn     10-60 deg at a peak speed of 50-300 deg/s (head gaze shifts: Zangemeister et al. 1981,
           Exp Neurol 71:76), minimum-jerk, then hold.
Opt-in kinds (round 40; stress.py --motions; not among the kinds drawn by default, so that earlier seeds
draw what they drew), ranges assumed rather than taken from a measurement (their docstrings say why):
  gesture  a nod (pitch) or a shake (yaw): 1-3 Hz, 2-20 deg peak to peak, 1.5-4 cycles.
  dodge    a game's dodge or duck: the head out 10-50 cm sideways or 10-40 cm down and back, minimum-jerk.
"""

import numpy as np

RATE_HZ = 1000.0
# A trace covers its run and this much more, so that a run's last frame has its poses and the head speed
# around it.
TRACE_MARGIN_S = 0.5
NECK_TO_EYES = np.array([0.0, 0.07, -0.07])  # imu/motion_extra.h
TREMOR_BAND_HZ = (8.0, 12.0)


def _log_uniform(rng, lo, hi):
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


# --- quaternions (w, x, y, z), arrays of shape (..., 4) ---


def _qmul(a, b):
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def _qconj(q):
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def _from_rotation_vector(v):
    """Quaternions of rotation vectors (rad), shape (N, 3)."""
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    half = 0.5 * angle
    safe = np.where(angle > 1e-12, angle, 1.0)
    return np.concatenate([np.cos(half), np.where(angle > 1e-12, np.sin(half) / safe, 0.5) * v], axis=-1)


def _to_rotation_vector(q):
    q = np.where(q[..., :1] < 0, -q, q)
    s = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., :1])
    return np.where(s > 1e-12, angle / np.where(s > 1e-12, s, 1.0), 2.0) * q[..., 1:]


def _rotate(q, v):
    qv = np.concatenate([np.zeros(q.shape[:-1] + (1,)), np.broadcast_to(v, q.shape[:-1] + (3,))], axis=-1)
    return _qmul(_qmul(q, qv), _qconj(q))[..., 1:]


# --- components: each adds to the small rotation (deg, head axes), turns or translation ---


def _band_noise(rng, n, lo_hz, hi_hz):
    """Unit-RMS Gaussian noise with its spectrum confined to [lo_hz, hi_hz]."""
    spectrum = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, 1.0 / RATE_HZ)
    spectrum[(f < lo_hz) | (f > hi_hz)] = 0.0
    x = np.fft.irfft(spectrum, n)
    return x / max(x.std(), 1e-12)


def _minimum_jerk(tau):
    tau = np.clip(tau, 0.0, 1.0)
    return tau**3 * (10 - 15 * tau + 6 * tau**2)


def _random_direction(rng, max_tilt_deg):
    """A unit axis near the yaw axis (y), tilted towards pitch (x) by up to max_tilt_deg, either way."""
    tilt = np.radians(rng.uniform(-max_tilt_deg, max_tilt_deg))
    return (1.0 if rng.uniform() < 0.5 else -1.0) * np.array([np.sin(tilt), np.cos(tilt), 0.0])


class _Motion:
    def __init__(self, t):
        self.t = t
        self.small_deg = np.zeros((len(t), 3))  # small rotations (tremor, drift, sway, saccades)
        self.turns = []  # (axis, angle in rad over t): pursuits and turns, composed outside
        self.translation = np.zeros((len(t), 3))  # besides the neck model (m)


def tremor(m, rng, run_s):
    rms = _log_uniform(rng, 0.005, 0.5)
    for axis in range(3):
        m.small_deg[:, axis] += rms * _band_noise(rng, len(m.t), *TREMOR_BAND_HZ)
    return {"tremor_rms_deg": round(rms, 4)}


def drift(m, rng, run_s):
    speed = _log_uniform(rng, 0.02, 0.5)
    # Direction wandering by a slow random walk (about a radian per second).
    heading = rng.uniform(0, 2 * np.pi) + np.cumsum(rng.standard_normal(len(m.t))) / np.sqrt(RATE_HZ)
    m.small_deg[:, 0] += np.cumsum(speed * np.cos(heading)) / RATE_HZ
    m.small_deg[:, 1] += np.cumsum(speed * np.sin(heading)) / RATE_HZ
    return {"drift_deg_s": round(speed, 3)}


def sway(m, rng, run_s):
    f = rng.uniform(0.1, 1.0)
    yaw, pitch, side_m = rng.uniform(0.5, 6.0), rng.uniform(0.2, 3.0), rng.uniform(0.005, 0.03)
    phase = rng.uniform(0, 2 * np.pi, size=3)
    wave = lambda k: 0.5 * (np.sin(2 * np.pi * f * m.t + phase[k]) - np.sin(phase[k]))  # 0 at t = 0
    m.small_deg[:, 1] += yaw * wave(0)
    m.small_deg[:, 0] += pitch * wave(1)
    m.translation[:, 0] += side_m * wave(2)
    return {"sway_hz": round(f, 3), "sway_yaw_pp_deg": round(yaw, 2), "sway_side_pp_cm": round(100 * side_m, 2)}


def pursuit(m, rng, run_s):
    speed = np.radians(_log_uniform(rng, 3.0, 60.0))
    start = rng.uniform(0.1, 0.4) * run_s
    ramp_in, ramp_out = rng.uniform(0.1, 0.3), rng.uniform(0.05, 0.15)
    duration = rng.uniform(0.2, 0.5) * run_s  # at full speed, then stop and hold
    t = m.t - start
    v = speed * np.clip(np.minimum(t / ramp_in, 1.0 - (t - ramp_in - duration) / ramp_out), 0.0, 1.0)
    v[t < 0] = 0.0
    m.turns.append((_random_direction(rng, 45.0), np.cumsum(v) / RATE_HZ))
    return {"pursuit_deg_s": round(np.degrees(speed), 2), "pursuit_stop_s": round(start + ramp_in + duration, 3)}


def saccade(m, rng, run_s):
    size = _log_uniform(rng, 0.05, 1.0)
    duration = (21.0 + 2.2 * size) / 1000.0
    start = rng.uniform(0.2, 0.8) * run_s
    angle = rng.uniform(0, 2 * np.pi)
    s = _minimum_jerk((m.t - start) / duration)
    m.small_deg[:, 0] += size * np.cos(angle) * s
    m.small_deg[:, 1] += size * np.sin(angle) * s
    return {"saccade_deg": round(size, 3), "saccade_s": round(start, 3)}


def turn(m, rng, run_s):
    size, peak = rng.uniform(10.0, 60.0), _log_uniform(rng, 50.0, 300.0)
    duration = 1.875 * size / peak  # minimum jerk: peak speed = 1.875 amplitude / duration
    start = rng.uniform(0.2, 0.6) * run_s
    m.turns.append((_random_direction(rng, 20.0), np.radians(size) * _minimum_jerk((m.t - start) / duration)))
    return {"turn_deg": round(size, 1), "turn_peak_deg_s": round(peak, 1), "turn_s": round(start, 3)}


def gesture(m, rng, run_s):
    """A nod (about the pitch axis) or a shake (yaw): a sine of 1-3 Hz and 2-20 deg peak to peak under a
    sin^2 envelope (it starts and ends at rest), 1.5-4 cycles from 0.1-0.4 of the run, shortened to end
    by 0.95 of it. Assumed ranges, chosen to reach between the corpus's sway (0.25-0.35 Hz) and its
    turns: the peak speed pi f pp reaches about 190 deg/s, and the head reverses every 1/(2f) s."""
    axis = 0 if rng.uniform() < 0.5 else 1
    f, pp = rng.uniform(1.0, 3.0), _log_uniform(rng, 2.0, 20.0)
    start = rng.uniform(0.1, 0.4) * run_s
    duration = min(rng.uniform(1.5, 4.0) / f, 0.95 * run_s - start)
    tau = (m.t - start) / duration
    envelope = np.where((tau >= 0.0) & (tau <= 1.0), np.sin(np.pi * np.clip(tau, 0.0, 1.0)) ** 2, 0.0)
    m.small_deg[:, axis] += 0.5 * pp * np.sin(2 * np.pi * f * (m.t - start)) * envelope
    return {"gesture": "nod" if axis == 0 else "shake", "gesture_hz": round(f, 3), "gesture_pp_deg": round(pp, 2),
            "gesture_s": round(start, 3), "gesture_end_s": round(start + duration, 3)}


def dodge(m, rng, run_s):
    """A dodge (sideways, 10-50 cm) or a duck (down, 10-40 cm), as games with obstacles ask of a player: out
    in 0.25-0.5 s, held 0.1-0.4 s, back in 0.25-0.5 s, each minimum-jerk, from 0.1-0.3 of the run (a short run
    holds only its start). Assumed ranges: a lean of the torso and a squat's first part; the peak speed
    1.875 amount / duration reaches 3.75 m/s, a translation no scene of the corpus has (lean: 10-20 cm
    over 1-2 s)."""
    duck = rng.uniform() < 0.5
    amount = rng.uniform(0.10, 0.40) if duck else rng.uniform(0.10, 0.50) * (1.0 if rng.uniform() < 0.5 else -1.0)
    out_s, hold_s, back_s = rng.uniform(0.25, 0.5), rng.uniform(0.1, 0.4), rng.uniform(0.25, 0.5)
    start = rng.uniform(0.1, 0.3) * run_s
    t = m.t - start
    offset = _minimum_jerk(t / out_s) - _minimum_jerk((t - out_s - hold_s) / back_s)
    m.translation[:, 1 if duck else 0] += (-amount if duck else amount) * offset
    return {"dodge": "duck" if duck else "side", "dodge_cm": round(100 * amount, 1),
            "dodge_peak_m_s": round(1.875 * abs(amount) / min(out_s, back_s), 2), "dodge_s": round(start, 3)}


COMPONENTS = {"tremor": tremor, "drift": drift, "sway": sway, "pursuit": pursuit, "saccade": saccade, "turn": turn}
# A trace kind: its main component; every kind carries tremor (the physiological baseline), "mix"
# two or three of the others on top of it.
KINDS = ["tremor", "drift", "sway", "pursuit", "saccade", "turn", "mix"]
# Round 40: kinds drawn only when asked for (stress.py --motions), each its component on top of tremor; "mix"
# never takes them, so that the default kinds draw what they drew.
OPT_IN_COMPONENTS = {"gesture": gesture, "dodge": dodge}
OPT_IN_KINDS = list(OPT_IN_COMPONENTS)


def make_trace(kind, rng, run_s, cover_s=None):
    """(rows as an (N, 11) array, parameters drawn) of one trace of this kind covering cover_s (by default
    run_s + TRACE_MARGIN_S); its motion is drawn for a run of run_s."""
    t = np.arange(0.0, run_s + TRACE_MARGIN_S if cover_s is None else cover_s, 1.0 / RATE_HZ)
    m = _Motion(t)
    params = {"kind": kind}
    parts = ["tremor"]
    if kind == "mix":
        others = [c for c in COMPONENTS if c != "tremor"]
        parts += list(rng.choice(others, size=int(rng.integers(2, 4)), replace=False))
    elif kind != "tremor":
        parts.append(kind)
    for part in parts:
        params.update({**COMPONENTS, **OPT_IN_COMPONENTS}[part](m, rng, run_s))
    q = _from_rotation_vector(np.radians(m.small_deg))
    for axis, angle in m.turns:
        q = _qmul(_from_rotation_vector(angle[:, None] * axis), q)
    # Head-frame angular velocity: the rotation between neighbouring samples, central differences.
    q_next = np.concatenate([q[1:], q[-1:]])
    q_prev = np.concatenate([q[:1], q[:-1]])
    span = np.full(len(t), 2.0 / RATE_HZ)
    span[0] = span[-1] = 1.0 / RATE_HZ
    omega = _to_rotation_vector(_qmul(_qconj(q_prev), q_next)) / span[:, None]
    position = _rotate(q, NECK_TO_EYES) - NECK_TO_EYES + m.translation
    return np.column_stack([t, q, omega, position]), params


def write_trace(path, rows):
    header = "t_s,qw,qx,qy,qz,wx,wy,wz,px,py,pz"
    np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt="%.9g")
