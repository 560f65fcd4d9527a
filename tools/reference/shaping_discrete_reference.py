#!/usr/bin/env python3
"""Reference values for the shaper discretization, the real-time shaper and the shaped toolpath
(servotwin::shaping discretization / realtime_shaper / shaped_path tests).

Independent of the C++ code:
* ZV4 shapers are designed from the catalog's C6.2 formulas (p1, p2, p3 -> t_i, A_i);
* the exact discretization splits each off-grid pulse by solving the 2x2 real linear system
  "value of the two grid pulses at the design pole == value of the original pulse" with
  numpy.linalg.solve (not the closed-form sine ratios the library uses), merges, renormalizes;
* residuals are |sum A_i exp(-s t_i)| evaluated with complex arithmetic at s = -zeta w + j w_d;
* the shaped-step modal amplitude comes from scipy.signal.cont2discrete + dlsim of the mode;
* p1 grid adjustment by brute force over every integer sample count;
* the 90-degree-corner deviation: convolution of the corner trajectory by numpy.convolve and the
  distance to the two half-lines (x <= 0, y = 0) and (x = 0, y >= 0) in closed form.

Writes tests/data/shaping/discrete_reference.json.
"""
import json
import math
import os

import numpy as np
from scipy import signal


def zv4(wn, zeta, p1, p2, p3=0.0):
    wd = wn * math.sqrt(1 - zeta * zeta)
    if p1 != 0:
        al = p1 * 2 * math.pi / 3
        a = abs(al)
        if a <= math.pi / 2:
            a2 = max(0.0, 2 * math.cos(a)) + p2 / (1 - p2)
        else:
            a2 = max(0.0, math.sin(3 * a) / math.sin(2 * a)) * p2
        a3 = (a2 * math.sin(2 * a) - math.sin(3 * a)) / math.sin(a)
        a4 = (a2 * math.sin(a) - math.sin(2 * a)) / math.sin(a)
    else:
        al = 0.0
        a2 = p2 / (1 - p2)
        a3 = max(a2 - 1, p3 / (1 - p3))
        a4 = 1 - a2 + a3
    T = (math.pi - al) / wd
    t = np.array([0, T, 2 * T, 3 * T])
    abar = np.array([1, a2, a3, a4]) * np.exp(-zeta * wn * t)
    return t, abar / abar.sum()


def pole(wn, zeta):
    return complex(-zeta * wn, wn * math.sqrt(1 - zeta * zeta))


def is_value(t, A, s):
    return complex(np.sum(np.asarray(A) * np.exp(-s * np.asarray(t))))


def residual(t, A, wn, zeta):
    """Catalog C6.3: Ar = exp(-zeta w t_n) sqrt(C^2 + S^2) = exp(-zeta w t_n) |IS(s)| (s the pole)."""
    return math.exp(-zeta * wn * t[-1]) * abs(is_value(t, A, pole(wn, zeta)))


def exact_discretize(t, A, wn, zeta, ts):
    s = pole(wn, zeta)
    out = {}
    for ti, Ai in zip(t, A):
        k = ti / ts
        kr = round(k)
        if abs(k - kr) <= 1e-9:
            out[kr] = out.get(kr, 0.0) + Ai
            continue
        k0 = math.floor(k)
        target = Ai * np.exp(-s * ti)
        z0, z1 = np.exp(-s * k0 * ts), np.exp(-s * (k0 + 1) * ts)
        M = np.array([[z0.real, z1.real], [z0.imag, z1.imag]])
        x = np.linalg.solve(M, np.array([target.real, target.imag]))
        out[k0] = out.get(k0, 0.0) + x[0]
        out[k0 + 1] = out.get(k0 + 1, 0.0) + x[1]
    keys = sorted(out)
    amps = np.array([out[k] for k in keys])
    return [int(k) for k in keys], (amps / amps.sum()).tolist()


def round_discretize(t, A, ts):
    out = {}
    for ti, Ai in zip(t, A):
        k = int(math.floor(ti / ts + 0.5))
        out[k] = out.get(k, 0.0) + Ai
    keys = sorted(out)
    return keys, [out[k] for k in keys]


def case(name, wn, zeta, p1, p2, p3, ts):
    t, A = zv4(wn, zeta, p1, p2, p3)
    kd, Ad = exact_discretize(t, A, wn, zeta, ts)
    kr, Ar = round_discretize(t, A, ts)
    return {
        "name": name, "omega": wn, "zeta": zeta, "p1": p1, "p2": p2, "p3": p3, "ts": ts,
        "times": t.tolist(), "amplitudes": A.tolist(),
        "exact": {"delays": kd, "amplitudes": Ad,
                  "residual": residual(np.array(kd) * ts, Ad, wn, zeta)},
        "round": {"delays": kr, "amplitudes": Ar,
                  "residual": residual(np.array(kr) * ts, Ar, wn, zeta),
                  "modal_ratio": abs(is_value(np.array(kr) * ts, Ar, pole(wn, zeta)))},
    }


def modal_ratio_by_simulation(delays, amps, wn, zeta, ts):
    """|z_shaped| / |z_unshaped| after the shaper ended, z = y' - conj(s) (y - 1) the modal
    coordinate of P(s) = wn^2 / (s^2 + 2 zeta wn s + wn^2), both driven by (shaped) unit steps
    held by a ZOH."""
    A = np.array([[0, 1], [-wn * wn, -2 * zeta * wn]])
    B = np.array([[0], [wn * wn]])
    C = np.eye(2)
    D = np.zeros((2, 1))
    Ad, Bd, Cd, Dd, _ = signal.cont2discrete((A, B, C, D), ts, method="zoh")
    n = delays[-1] + 40
    step = np.ones(n)
    shaped = np.convolve(step, np.bincount(delays, weights=amps))[:n]
    s = pole(wn, zeta)
    k = n - 1

    def z(u):
        _, y, _ = signal.dlsim((Ad, Bd, Cd, Dd, ts), u)
        return y[k, 1] - np.conj(s) * (y[k, 0] - 1)

    return abs(z(shaped)) / abs(z(step))


def p1_grid(wn, zeta, p1, ts):
    """Brute force: every sample count m whose p1 = 3 (pi - wd m ts) / (2 pi) lies in [-1, 1];
    the one nearest the requested p1 (ties: the larger m, i.e. the longer, more robust filter)."""
    wd = wn * math.sqrt(1 - zeta * zeta)
    best = None
    for m in range(1, 100000):
        q = 3 * (math.pi - wd * m * ts) / (2 * math.pi)
        if q < -1 - 1e-12:
            break
        if q > 1 + 1e-12:
            continue
        if best is None or abs(q - p1) <= abs(best[1] - p1):
            best = (m, q)
    return {"omega": wn, "zeta": zeta, "p1": p1, "ts": ts, "samples": best[0], "p1_grid": best[1]}


def corner(wn, zeta, p1, p2, ts, v, n_before, n_after):
    """Corner trajectory: along +x at speed v into the origin (sample n_before), then along +y."""
    t, A = zv4(wn, zeta, p1, p2)
    kd, Ad = exact_discretize(t, A, wn, zeta, ts)
    h = np.bincount(kd, weights=Ad)
    k = np.arange(n_before + n_after + 1)
    tau = (k - n_before) * ts
    x = np.where(tau < 0, v * tau, 0.0)
    y = np.where(tau > 0, v * tau, 0.0)
    # Before the trajectory, the shaper's memory holds the first sample; after it, the last one.
    pad_x = np.concatenate([np.full(len(h), x[0]), x, np.full(len(h), x[-1])])
    pad_y = np.concatenate([np.full(len(h), y[0]), y, np.full(len(h), y[-1])])
    sx = np.convolve(pad_x, h)[len(h):len(h) + len(k) + len(h) - 1]
    sy = np.convolve(pad_y, h)[len(h):len(h) + len(k) + len(h) - 1]
    # Distance to the union of the two half-lines (the shaped points lie in x <= 0, y >= 0).
    d_xaxis = np.where(sx <= 0, np.abs(sy), np.hypot(sx, sy))
    d_yaxis = np.where(sy >= 0, np.abs(sx), np.hypot(sx, sy))
    d = np.minimum(d_xaxis, d_yaxis)
    i = int(np.argmax(d))
    return {"omega": wn, "zeta": zeta, "p1": p1, "p2": p2, "ts": ts, "v": v, "n_before": n_before,
            "times": t.tolist(), "amplitudes": A.tolist(), "delays": kd, "discrete_amplitudes": Ad,
            "n_after": n_after, "max_deviation": float(d[i]), "max_index": i,
            "rms_deviation": float(np.sqrt(np.mean(d * d))), "samples": int(len(d)),
            "max_point": [float(sx[i]), float(sy[i])]}


def main():
    cases = [
        case("E16/E18", 1.0, 0.01, 0.5, 0.5, 0.0, 0.5),
        case("10 Hz, zeta 0.05, p1 -0.3, p2 0.3, ts 4 ms", 2 * math.pi * 10, 0.05, -0.3, 0.3, 0.0, 0.004),
        case("ZVDD 3 Hz, zeta 0.1, ts 7 ms", 2 * math.pi * 3, 0.1, 0.0, 0.75, 0.75, 0.007),
        case("0.8 Hz, zeta 0.2, p1 0.9, p2 0.2, ts 0.3 s (Ts near half a period)", 2 * math.pi * 0.8, 0.2, 0.9, 0.2, 0.0, 0.3),
    ]
    e18 = cases[0]
    e18["exact"]["modal_ratio_simulated"] = modal_ratio_by_simulation(e18["exact"]["delays"], e18["exact"]["amplitudes"], 1.0, 0.01, 0.5)
    e18["round"]["modal_ratio_simulated"] = modal_ratio_by_simulation(e18["round"]["delays"], e18["round"]["amplitudes"], 1.0, 0.01, 0.5)
    grids = [p1_grid(1.0, 0.01, 0.5, 0.5), p1_grid(2 * math.pi * 10, 0.05, 0.5, 0.001),
             p1_grid(2 * math.pi * 10, 0.05, -0.3, 0.004), p1_grid(2 * math.pi * 23.7, 0.0, 0.0, 0.0005)]
    corners = [corner(2 * math.pi * 10, 0.02, 0.5, 0.3, 0.001, 100.0, 200, 200)]
    doc = {"generator": "tools/reference/shaping_discrete_reference.py", "cases": cases,
           "p1_grid": grids, "corner": corners}
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "..", "tests", "data", "shaping", "discrete_reference.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    for c in cases:
        print(c["name"], "exact", c["exact"], "\n round", c["round"])
    print(grids)
    print(corners)


if __name__ == "__main__":
    main()
