#!/usr/bin/env python3
"""Reference statistics for the rapid-identification regression (tests/rapid/test_regression_reference.cpp).

Writes tests/data/rapid/regression_reference.json: a deterministic synthetic capture and, for
several option sets, the regressor statistics P = Phi^T Phi, R = Phi^T y, Gamma = y^T y, the row
and direction counts, the automatic deadband and the unconstrained least-squares parameters.

Everything is computed independently of the C++ code, directly from the documented conventions
(include/servotwin/rapid/regression.hpp, thesis Eq. 3.9-3.11):
  * pairs (x_r,k, x_k) = (cmd[k + shift], act[k]) for the k where cmd[k + shift] exists;
  * e_i,k = ts * sum_{m=0..k} (x_r,m - x_m) (cumulative sum in 80-bit long double);
  * xdot_k = (x_{k+1} - x_{k-1}) / (2 ts), xddot_k = (xdot_{k+1} - xdot_{k-1}) / (2 ts), rows k = 2..M-3,
    then trim_start / trim_end rows dropped;
  * PV = xdot > deadband (1 + 1e-9), NV = xdot < -deadband (1 + 1e-9) (ties count as inside); automatic deadband = max(1.25 q / ts, 4 sigma_v),
    sigma_v = 1.4826 median |x_{k+1} - 2 x_k + x_{k-1}| / sqrt(6) / (sqrt(2) ts) over standstill rows,
    estimated over the window of `deadband_window` pairs that starts 2 pairs before the first
    (not trimmed) row with nonzero xdot;
  * Gram entries summed with math.fsum (exactly rounded sums of the rounded products);
  * theta by numpy.linalg.lstsq on the column-equilibrated Phi.

The capture: random point-to-point moves within +-8 mm (trapezoidal velocity, 150 mm/s,
1500 mm/s^2, random dwells) followed by a P-PI-like loop (semi-implicit Euler of an integrating
second-order loop with Coulomb friction), position quantized to 0.1 um with a small Gaussian
noise before quantization, ts = 1 ms, 3000 samples.

Run:  /usr/bin/python3 tools/reference/regression_reference.py
"""

import json
import math
import os

import numpy as np

TS = 1e-3
SAMPLES = 3000
RESOLUTION = 1e-4
OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "rapid", "regression_reference.json")


def capture():
    rng = np.random.default_rng(20070101)
    v_max, a_max = 150.0, 1500.0
    # Command: list of (duration, acceleration) pieces, integrated exactly per sample.
    t_end = SAMPLES * TS
    pieces = []
    x, t = 0.0, 0.0
    while t < t_end + 0.5:
        goal = rng.uniform(-8.0, 8.0)
        d = abs(goal - x)
        s = 1.0 if goal > x else -1.0
        ta = min(v_max / a_max, math.sqrt(d / a_max))
        vp = a_max * ta
        tc = max(0.0, (d - vp * ta) / vp)
        pieces += [(ta, s * a_max), (tc, 0.0), (ta, -s * a_max), (rng.uniform(0.0, 0.08), 0.0)]
        t += 2 * ta + tc + pieces[-1][0]
        x = goal
    starts = np.cumsum([0.0] + [p[0] for p in pieces])

    def command_at(time):
        i = int(np.searchsorted(starts, time, side="right")) - 1
        pos, vel = 0.0, 0.0
        for j in range(i):  # replay the pieces up to i (exact kinematics)
            dur, acc = pieces[j]
            pos += vel * dur + 0.5 * acc * dur * dur
            vel += acc * dur
        tau = time - starts[i]
        acc = pieces[i][1]
        return pos + vel * tau + 0.5 * acc * tau * tau

    cmd = np.array([command_at(k * TS) for k in range(SAMPLES)])
    # Axis: x'' = kv (kp (r - x) + ki z - x') - friction, integrated with 10 substeps.
    kp, ki, kv = 120.0, 400.0, 600.0
    friction_pos, friction_neg = 300.0, -250.0
    h = TS / 10
    z = pos = vel = 0.0
    act = np.empty(SAMPLES)
    noise = rng.normal(0.0, 0.3 * RESOLUTION, SAMPLES)
    for k in range(SAMPLES):
        act[k] = RESOLUTION * round((pos + noise[k]) / RESOLUTION)
        for i in range(10):
            r = np.interp(k * TS + i * h, [k * TS, (k + 1) * TS], [cmd[k], cmd[min(k + 1, SAMPLES - 1)]])
            friction = friction_pos if vel > 0 else (friction_neg if vel < 0 else 0.0)
            acc = kv * (kp * (r - pos) + ki * z - vel) - friction
            z += h * (r - pos)
            vel += h * acc
            pos += h * vel
    # Round through decimal text so that the JSON values are exactly the doubles used.
    return [float(repr(float(c))) for c in cmd], [float(repr(float(a))) for a in act]


def automatic_deadband(r, x, first_row, window):
    m = len(x)
    begin = None
    for k in range(first_row, m - 2):
        if x[k + 1] != x[k - 1]:
            begin = k - 2
            break
    if begin is None:
        return 0.0, 0.0, 0.0
    end = min(begin + window, m)
    steps = [abs(x[k + 1] - x[k]) for k in range(begin, end - 1)
             if abs(x[k + 1] - x[k]) > 1e3 * np.finfo(float).eps * max(abs(x[k]), abs(x[k + 1]))]
    q = min(steps) if steps else 0.0
    still = [abs(x[k + 1] - 2 * x[k] + x[k - 1]) for k in range(begin + 2, end - 2)
             if r[k - 2] == r[k - 1] == r[k] == r[k + 1] == r[k + 2]]
    # sigma_x = 1.4826 median |second difference| / sqrt(6); velocity noise sigma_x / (sqrt(2) ts)
    noise = 1.4826 * float(np.median(still)) / math.sqrt(6.0) / (math.sqrt(2.0) * TS) if len(still) >= 16 else 0.0
    return max(1.25 * q / TS, 4.0 * noise), q, noise


def case(cmd, act, shift=0, trim_start=0, trim_end=0, deadband=None, window=2048):
    n = len(cmd)
    ks = [k for k in range(n) if 0 <= k + shift < n]
    r = [cmd[k + shift] for k in ks]
    x = [act[k] for k in ks]
    m = len(x)
    diff = np.array(r, dtype=np.longdouble) - np.array(x, dtype=np.longdouble)
    ei = np.longdouble(TS) * np.cumsum(diff)
    rows = list(range(2 + trim_start, m - 2 - trim_end))
    if deadband is None:
        db, q, noise = automatic_deadband(r, x, 2 + trim_start, window)
    else:
        db, q, noise = deadband, 0.0, 0.0

    def vel(s, k):
        return (s[k + 1] - s[k - 1]) / (2 * TS)

    phi, y = [], []
    for k in rows:
        xd = vel(x, k)
        xdd = (vel(x, k + 1) - vel(x, k - 1)) / (2 * TS)
        rd = vel(r, k)
        rdd = (vel(r, k + 1) - vel(r, k - 1)) / (2 * TS)
        band = db * (1.0 + 1e-9)
        pv = 1.0 if xd > band else 0.0
        nv = 1.0 if xd < -band else 0.0
        phi.append([float(ei[k]), -xd, -xdd, r[k], rd, rdd, -pv, -nv])
        y.append(x[k])
    phi = np.array(phi)
    y = np.array(y)
    P = [[math.fsum(phi[:, i] * phi[:, j]) for j in range(8)] for i in range(8)]
    R = [math.fsum(phi[:, i] * y) for i in range(8)]
    gamma = math.fsum(y * y)
    norms = np.linalg.norm(phi, axis=0)
    norms[norms == 0] = 1.0
    z = np.linalg.lstsq(phi / norms, y, rcond=None)[0]
    theta = z / norms
    return {
        "options": {"command_shift": shift, "trim_start": trim_start, "trim_end": trim_end,
                    "velocity_deadband": deadband, "deadband_window": window},
        "rows": len(rows),
        "positive_rows": int(np.sum(phi[:, 6] != 0)),
        "negative_rows": int(np.sum(phi[:, 7] != 0)),
        "velocity_deadband": db,
        "position_resolution": q,
        "velocity_noise": noise,
        "first_row": {"phi": phi[0].tolist(), "y": float(y[0])},
        "last_row": {"phi": phi[-1].tolist(), "y": float(y[-1])},
        "P": P,
        "R": R,
        "Gamma": gamma,
        "theta": theta.tolist(),
    }


def main():
    cmd, act = capture()
    data = {
        "generator": "tools/reference/regression_reference.py",
        "ts": TS,
        "command": cmd,
        "actual": act,
        "cases": {
            "automatic": case(cmd, act),
            "shifted_trimmed": case(cmd, act, shift=2, trim_start=25, trim_end=40, deadband=4.975),
            "negative_shift_small_window": case(cmd, act, shift=-3, trim_start=300, window=64),
        },
    }
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    for name, c in data["cases"].items():
        print(name, c["rows"], c["positive_rows"], c["negative_rows"], c["velocity_deadband"],
              c["position_resolution"], c["velocity_noise"])


if __name__ == "__main__":
    main()
