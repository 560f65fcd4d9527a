#!/usr/bin/env python3
"""Reference values for the shaping module (servotwin::shaping), written to tests/data/shaping/.

Independent of the C++ code: every shaper is computed here from its defining conditions with
numpy/scipy (different formulation: complex residual sums, scipy.optimize.fsolve with numeric
derivatives for the EI family), and the smoothing measure is evaluated from the corner
trajectories themselves (piecewise position functions sampled at the shifted impulse times)
rather than from a per-leg closed form.

Sources of the definitions:
  * residual vibration V(w, z): catalog C6.3 (Singer-Seering normalized residual);
  * ZV4: catalog C6.2 with a3 = max{...} (defect 1), printed examples E16, E19, E20, E35;
  * ZV / ZVD / ZVDD / MZV / EI family: Singer & Seering 1990, Singhose et al. 1994/1996 (defining
    conditions); Klipper (docs/Resonance_Compensation.md, klippy/extras/shaper_defs.py) for the
    meaning of the names (MZV: 3 impulses over 0.75 damped periods);
  * Klipper's curve fits of the EI family (Singhose's polynomial fits in zeta) are evaluated
    only to *record how far they are* from the exact solutions (fixture "klipper_fit_difference").

Run:  python3 tools/reference/shaping_reference.py   (rewrites tests/data/shaping/*.json)
"""
import json
import math
import os

import numpy as np
from scipy.optimize import fsolve, brentq

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "shaping")


def residual(times, amps, w, z):
    times = np.asarray(times, float)
    amps = np.asarray(amps, float)
    wd = w * math.sqrt(1 - z * z)
    r = np.sum(amps * np.exp(z * w * times) * np.exp(1j * wd * times))
    return abs(r) * math.exp(-z * w * times[-1]) / amps.sum()


def norm(amps):
    a = np.asarray(amps, float)
    return list(a / a.sum())


# ---------------------------------------------------------------- ZV4 (C6.2)
def zv4(wn, z, p1, p2, p3=0.0):
    if p1 == 0:
        a2 = p2 / (1 - p2)
        a3 = max(a2 - 1, p3 / (1 - p3))
        a = [1, a2, a3, 1 - a2 + a3]
        alpha = 0.0
    else:
        alpha = p1 * 2 * math.pi / 3
        al = abs(alpha)
        s1, s2, s3 = math.sin(al), math.sin(2 * al), math.sin(3 * al)
        if al <= math.pi / 2:
            a2 = max(0.0, 2 * math.cos(al)) + p2 / (1 - p2)
        else:
            a2 = max(0.0, s3 / s2) * p2
        a = [1, a2, (a2 * s2 - s3) / s1, (a2 * s1 - s2) / s1]
    wd = wn * math.sqrt(1 - z * z)
    T = (math.pi - alpha) / wd
    big = max(a)
    t, A = [], []
    for i, ai in enumerate(a):
        if ai < 1e-12 * big:
            continue
        t.append(i * T)
        A.append(ai * math.exp(-z * wn * i * T))
    return t, norm(A)


def hump_height(times, amps, z=0.0):
    """The lower hump: the local maximum of V between 0.6 and 1 rad/s (design frequency 1)."""
    ws = np.linspace(0.6, 1.0, 20001)
    v = [residual(times, amps, w, z) for w in ws]
    i = max((k for k in range(1, len(ws) - 1) if v[k] >= v[k - 1] and v[k] >= v[k + 1]), key=lambda k: v[k])
    return max(residual(times, amps, w, z) for w in np.linspace(ws[max(i - 1, 0)], ws[min(i + 1, len(ws) - 1)], 2001))


def zv4_cases():
    cases = []
    for name, wn, z, p1, p2, p3 in [
        ("E16", 1.0, 0.01, 0.5, 0.5, 0.0),
        ("E35 gantry crane", 4.22, 0.0079, 0.3, 0.5, 0.0),
        ("E20 p1=0.3 p2=0.1", 1.0, 0.0, 0.3, 0.1, 0.0),
        ("E20 p1=-0.5 p2=0.1", 1.0, 0.0, -0.5, 0.1, 0.0),
        ("E20 p1=1", 1.0, 0.0, 1.0, 0.3, 0.0),
        ("E20 p1=-1", 1.0, 0.0, -1.0, 0.3, 0.0),
        ("p1=0.8 damped", 50.0, 0.1, 0.8, 0.4, 0.0),
        ("p1=-0.2 damped", 30.0, 0.2, -0.2, 0.25, 0.0),
        ("p1=0 p3 large damped", 10.0, 0.05, 0.0, 0.6, 0.3),
        ("boundary p2=0", 2.0, 0.0, 0.4, 0.0, 0.0),
    ]:
        t, A = zv4(wn, z, p1, p2, p3)
        cases.append({"name": name, "omega": wn, "zeta": z, "p1": p1, "p2": p2, "p3": p3, "times": t,
                      "amplitudes": A, "residual_at_design": residual(t, A, wn, z)})
    table = []
    for name, p2, p3 in [("zv", 0.5, 0.0), ("zvd", 2 / 3, 0.5), ("zvdd", 0.75, 0.75), ("2hei5", 0.6803, 0.6803),
                         ("2hei2_printed", 0.7075, 0.7075), ("2hei2", 0.713573, 0.713573), ("2hei1", 0.7274, 0.7274)]:
        t, A = zv4(1.0, 0.0, 0.0, p2, p3)
        row = {"name": name, "p2": p2, "p3": p3, "times": t, "amplitudes": A}
        if name.startswith("2hei"):
            row["hump_height"] = hump_height(t, A)
        table.append(row)
    return {"source": "tools/reference/shaping_reference.py: catalog C6.2 (max fix), E16/E19/E20/E35",
            "cases": cases, "table_6_1": table}


# ---------------------------------------------------------------- classic families
def binomial(wn, z, order):
    wd = wn * math.sqrt(1 - z * z)
    K = math.exp(-z * math.pi / math.sqrt(1 - z * z))
    return [i * math.pi / wd for i in range(order + 1)], norm([math.comb(order, i) * K ** i for i in range(order + 1)])


def mzv(wn, z):
    """Defining conditions: impulses at damped phases 0, 3pi/4, 3pi/2 and zero vibration at (wn, z).
    Solve the 3x3 linear system [sum A = 1, Re R = 0, Im R = 0] for A."""
    wd = wn * math.sqrt(1 - z * z)
    t = np.array([0, 0.75 * math.pi / wd, 1.5 * math.pi / wd])
    e = np.exp(z * wn * t)
    M = np.vstack([np.ones(3), e * np.cos(wd * t), e * np.sin(wd * t)])
    A = np.linalg.solve(M, [1, 0, 0])
    return list(t), list(A)


def classic_cases():
    out = []
    for wn, z in [(2 * math.pi * 50, 0.1), (2 * math.pi * 34.6, 0.0), (7.5, 0.3), (2 * math.pi * 4.22 / (2 * math.pi), 0.0079)]:
        for name, f in [("zv", lambda w, zz: binomial(w, zz, 1)), ("zvd", lambda w, zz: binomial(w, zz, 2)),
                        ("zvdd", lambda w, zz: binomial(w, zz, 3)), ("mzv", mzv)]:
            t, A = f(wn, z)
            out.append({"type": name, "omega": wn, "zeta": z, "times": list(map(float, t)),
                        "amplitudes": list(map(float, A)), "residual_at_design": residual(t, A, wn, z)})
    return out


# ---------------------------------------------------------------- EI family, exact
def ei_closed_form(kind, V):
    pi = math.pi
    if kind == "ei":
        A = [(1 + V) / 4, (1 - V) / 2, (1 + V) / 4]
    elif kind == "2hump_ei":
        X = (V * V * (math.sqrt(1 - V * V) + 1)) ** (1 / 3)
        a1 = (3 * X * X + 2 * X + 3 * V * V) / (16 * X)
        A = [a1, 0.5 - a1, 0.5 - a1, a1]
    else:
        a1 = (1 + 3 * V + 2 * math.sqrt(2 * V * (V + 1))) / 16
        a2 = (1 - V) / 4
        A = [a1, a2, 1 - 2 * (a1 + a2), a2, a1]
    return [i * pi for i in range(len(A))], A


def critical_points(t, A, z):
    """Zeros (local minima with V ~ 0) and humps (local maxima) of V on (0.3, 1.7) rad/s, found by
    a dense scan: the initial guesses of the fsolve system."""
    ws = np.linspace(0.3, 1.7, 14001)
    v = np.array([residual(t, A, w, z) for w in ws])
    mins = [ws[i] for i in range(1, len(ws) - 1) if v[i] < v[i - 1] and v[i] <= v[i + 1] and v[i] < 1e-2]
    maxs = [ws[i] for i in range(1, len(ws) - 1) if v[i] > v[i - 1] and v[i] >= v[i + 1]]
    return mins, maxs


def complex_r(x_t, x_a, w, z):
    t = np.asarray(x_t)
    a = np.asarray(x_a)
    wd = w * math.sqrt(1 - z * z)
    return np.sum(a * np.exp(-z * w * (t[-1] - t)) * np.exp(1j * wd * t))


def solve_ei(kind, z, V):
    """Same defining conditions as the C++ (families.hpp), a different formulation: unknowns as in
    the C++, but the hump conditions use |R| and a central-difference d|R|^2/dw, solved by fsolve
    with continuation in zeta."""
    t0, A0 = ei_closed_form(kind, V)
    n = len(A0)
    mins, maxs = critical_points(t0, A0, 0.0)
    if kind == "ei":
        design, humps, zeros = "hump", [], [w for w in mins if abs(w - 1) > 1e-3]
    elif kind == "2hump_ei":
        design, humps, zeros = "zero", maxs, [w for w in mins if abs(w - 1) > 1e-3]
    else:
        design, humps, zeros = "hump", [w for w in maxs if abs(w - 1) > 1e-3], mins
    x = np.array(A0 + t0[1:] + humps + zeros, float)
    nh, nz = len(humps), len(zeros)

    def eqs(x, zz):
        a = x[:n]
        t = np.concatenate([[0.0], x[n:2 * n - 1]])
        fr = x[2 * n - 1:]
        f = [a.sum() - 1]

        def zero(w):
            r = complex_r(t, a, w, zz)
            return [r.real, r.imag]

        def hump(w):
            # d|R|^2/dw = 2 Re(conj(R) dR/dw), dR/dw = sum a (-z (t_n - t) + j sqrt(1-z^2) t) e^{...}
            wd = w * math.sqrt(1 - zz * zz)
            terms = a * np.exp(-zz * w * (t[-1] - t)) * np.exp(1j * wd * t)
            r = np.sum(terms)
            dr = np.sum(terms * (-zz * (t[-1] - t) + 1j * math.sqrt(1 - zz * zz) * t))
            return [abs(r) - V, 2 * (np.conj(r) * dr).real]

        f += zero(1.0) if design == "zero" else hump(1.0)
        for k in range(nh):
            f += hump(fr[k])
        for k in range(nz):
            f += zero(fr[nh + k])
        return f

    steps = max(1, math.ceil(z / 0.025))
    for k in range(1, steps + 1):
        zz = z * k / steps
        x, info, ier, msg = fsolve(eqs, x, args=(zz,), xtol=1e-12, full_output=True)
        assert max(abs(v) for v in eqs(x, zz)) < 1e-12, (kind, zz, msg, eqs(x, zz))
    t = [0.0] + list(x[n:2 * n - 1])
    return t, list(x[:n]), list(x[2 * n - 1:])


def klipper_fit(kind, z, V=0.05):
    """Singhose's polynomial fits as used by Klipper (times in damped/undamped periods as Klipper
    defines them); only to quantify the difference from the exact solutions."""
    df = math.sqrt(1 - z * z)
    if kind == "ei":
        a1 = (0.24968 + 0.24961 * V) + ((0.80008 + 1.23328 * V) + (0.49599 + 3.17316 * V) * z) * z
        a3 = (0.25149 + 0.21474 * V) + ((-0.83249 + 1.41498 * V) + (0.85181 - 4.90094 * V) * z) * z
        t2 = 0.4999 + (((0.46159 + 8.57843 * V) * V) + (((4.26169 - 108.644 * V) * V) +
                                                        ((1.75601 + 336.989 * V) * V) * z) * z) * z
        td = 2 * math.pi / df
        return [0, t2 * td, td], norm([a1, 1 - a1 - a3, a3])
    if kind == "2hump_ei":
        tc = [[0, 0, 0, 0], [0.49890, 0.16270, -0.54262, 6.16180], [0.99748, 0.18382, -1.58270, 8.17120],
              [1.49920, -0.09297, -0.28338, 1.85710]]
        ac = [[0.16054, 0.76699, 2.26560, -1.22750], [0.33911, 0.45081, -2.58080, 1.73650],
              [0.34089, -0.61533, -0.68765, 0.42261], [0.15997, -0.60246, 1.00280, -0.93145]]
    else:
        tc = [[0, 0, 0, 0], [0.49974, 0.23834, 0.44559, 12.4720], [0.99849, 0.29808, -2.36460, 23.3990],
              [1.49870, 0.10306, -2.01390, 17.0320], [1.99960, -0.28231, 0.61536, 5.40450]]
        ac = [[0.11275, 0.76632, 3.29160, -1.44380], [0.23698, 0.61164, -2.57850, 4.85220],
              [0.30008, -0.19062, -2.14560, 0.13744], [0.23775, -0.73297, 0.46885, -2.08650],
              [0.11244, -0.45439, 0.96382, -1.46000]]
    poly = lambda c: sum(ci * z ** k for k, ci in enumerate(c))
    return [2 * math.pi * poly(c) for c in tc], norm([poly(c) for c in ac])


def ei_cases():
    out = []
    for kind, zetas, tols in [("ei", [0.0, 0.05, 0.1, 0.2, 0.3], [0.05, 0.02]),
                              ("2hump_ei", [0.0, 0.05, 0.1, 0.2], [0.05]),
                              ("3hump_ei", [0.0, 0.05, 0.1, 0.15], [0.05])]:
        for V in tols:
            for z in zetas:
                t, A, crit = solve_ei(kind, z, V)
                row = {"type": kind, "zeta": z, "v_tol": V, "times_wn1": t, "amplitudes": A,
                       "critical_frequencies_wn1": crit,
                       "residual_at_design": residual(t, A, 1.0, z)}
                if V == 0.05:
                    kt, kA = klipper_fit(kind, z)
                    row["klipper_fit_difference"] = {
                        "max_abs_amplitude": float(np.max(np.abs(np.array(kA) - np.array(A)))),
                        "max_abs_time_wn1": float(np.max(np.abs(np.array(kt) - np.array(t)))),
                        "klipper_residual_at_design": residual(kt, kA, 1.0, z)}
                out.append(row)
    return out


# ---------------------------------------------------------------- smoothing from the trajectories
def smoothing_from_trajectories(t, A, accel, scv):
    A = np.asarray(A, float) / np.sum(A)
    t = np.asarray(t, float)
    ts = float(np.sum(A * t))
    tau = t - ts

    def x_arrive(time):  # X decelerates into the corner and stops there
        return scv * time - 0.5 * accel * time * time if time < 0 else 0.0

    def y_leave(time):   # Y leaves the corner at scv, accelerating
        return scv * time + 0.5 * accel * time * time if time > 0 else 0.0

    xs = sum(a * x_arrive(-tt) for a, tt in zip(A, tau))
    ys = sum(a * y_leave(-tt) for a, tt in zip(A, tau))
    rev = sum(a * 0.5 * accel * (-tt) ** 2 for a, tt in zip(A, tau))  # x(t) = a t^2 / 2 at t = 0
    return {"corner_90": math.hypot(xs, ys), "reversal_180": rev, "smoothing": max(math.hypot(xs, ys), rev)}


def smoothing_cases():
    out = []
    for name, (t, A) in [("mzv 34.6 Hz z=0.1", mzv(2 * math.pi * 34.6, 0.1)),
                         ("zv 109.6 Hz z=0.1", binomial(2 * math.pi * 109.6, 0.1, 1)),
                         ("mzv 71.2 Hz z=0.1", mzv(2 * math.pi * 71.2, 0.1)),
                         ("zvd 40 Hz z=0.05", binomial(2 * math.pi * 40, 0.05, 2)),
                         ("zv4 E35", zv4(4.22, 0.0079, 0.3, 0.5))]:
        for accel, scv in [(5000.0, 5.0), (3000.0, 0.0), (1000.0, 20.0)]:
            row = {"name": name, "times": list(map(float, t)), "amplitudes": list(map(float, A)), "accel": accel, "scv": scv}
            row.update(smoothing_from_trajectories(t, A, accel, scv))
            out.append(row)
    return out


# ---------------------------------------------------------------- insensitivity bandwidth
def band(t, A, w0, z, level):
    f = lambda w: residual(t, A, w, z) - level
    ws = np.linspace(0.9 * w0, 1.1 * w0, 201)
    seed = min(ws, key=lambda w: residual(t, A, w, z))
    lo = seed
    while f(lo - 1e-4 * w0) <= 0:
        lo -= 1e-4 * w0
    hi = seed
    while f(hi + 1e-4 * w0) <= 0:
        hi += 1e-4 * w0
    lo = brentq(f, lo - 1e-4 * w0, lo, xtol=1e-14)
    hi = brentq(f, hi, hi + 1e-4 * w0, xtol=1e-14)
    return lo, hi


def band_cases():
    out = []
    for name, (t, A), z in [("zv undamped", binomial(1.0, 0.0, 1), 0.0), ("zvd undamped", binomial(1.0, 0.0, 2), 0.0),
                            ("zvdd z=0.05", binomial(1.0, 0.05, 3), 0.05), ("mzv z=0.1", mzv(1.0, 0.1), 0.1)]:
        for level in (0.05, 0.1):
            lo, hi = band(t, A, 1.0, z, level)
            out.append({"name": name, "times": list(map(float, t)), "amplitudes": list(map(float, A)), "omega": 1.0,
                        "zeta": z, "level": level, "omega_low": lo, "omega_high": hi})
    # the undamped ZV closed form: V = |cos(pi w / 2)|  ->  edges 2/pi acos(level) ... documented in the test
    return out


def main():
    os.makedirs(OUT, exist_ok=True)
    data = {
        "zv4.json": zv4_cases(),
        "classic.json": {"source": "tools/reference/shaping_reference.py: binomial ZV/ZVD/ZVDD, MZV by its defining conditions",
                         "cases": classic_cases()},
        "ei_family.json": {"source": "tools/reference/shaping_reference.py: EI family by fsolve on the defining conditions; "
                                     "klipper_fit_difference = Singhose's fits as used by Klipper minus exact",
                           "cases": ei_cases()},
        "smoothing.json": {"source": "tools/reference/shaping_reference.py: corner offsets evaluated on the trajectories",
                           "cases": smoothing_cases()},
        "bandwidth.json": {"source": "tools/reference/shaping_reference.py: brentq on V(w) - level", "cases": band_cases()},
    }
    for name, value in data.items():
        with open(os.path.join(OUT, name), "w") as f:
            json.dump(value, f, indent=1)
            f.write("\n")
        print("wrote", name)


if __name__ == "__main__":
    main()
