#!/usr/bin/env python3
"""Reference values for the direct LP synthesis of multi-mode input shapers (servotwin::shaping,
lp_shaper.hpp), written to tests/data/shaping/lp_multimode.json.

Formulation: catalog C6.3 / C6.4 (dissertation Sec. 6.3, eqs. 6.78 / 6.79, examples E22 / E23):
unknowns A_i >= 0 on the grid t_i = (i - 1) Tp, i = 1..n, with
  * sum A_i = 1;
  * per mode (w, z), w_d = w sqrt(1 - z^2), and per derivative order l = 0..d:
      sum A_i t_i^l e^{z w t_i} cos(w_d t_i) = 0,   sum A_i t_i^l e^{z w t_i} sin(w_d t_i) = 0;
  * per sensitivity point (w_s, z_s, S_max): |C|, |S| <= S_max e^{t_n z_s w_s} / sqrt(2) with
      C = sum A_i e^{z_s w_s t_i} cos(w_ds t_i), S likewise with sin (t_n = (n - 1) Tp, the grid end);
  * cost J2 = sum (k (i - 1) + 1) A_i (k > 0), or J1 = sum_{i >= 2} A_i (k = 0).

Independent of the C++ code (which uses GLPK's simplex on rows scaled by e^{-z w t_n} and t_n^-l):
this script states the constraints unscaled, exactly as printed, and solves them with HiGHS
(scipy.optimize.linprog(method="highs")). Where the optimum may not be unique (E23), the range of
every amplitude over the optimal face is recorded (minimize / maximize A_i subject to the
constraints and cost <= optimum + 1e-9), so the tests can tell a unique optimum from a face.

Sources of the expected numbers it reproduces: catalog E22 (printed A, Tf = 8.84 s, minimum n at
Tp = 0.63 / 0.68 / 0.75 s) and E23 (printed A feasible, 12 nonzero pulses).

Run:  /usr/bin/python3 tools/reference/shaping_lp_reference.py
"""
import json
import math
import os

import numpy as np
from scipy.optimize import linprog

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "shaping", "lp_multimode.json")

E_MODES = [(1.0, 0.1), (2.25, 0.1), (3.4, 0.1)]  # catalog E21-E23: rad/s, zeta
E22_PRINTED = [0.1492, 0, 0.1138, 0.0539, 0.0922, 0.1172, 0.1078, 0.1320, 0.0245, 0.0867, 0.0237,
               0.0559, 0.0196, 0.0235]
E23_PRINTED = [0.2317, 0, 0.0546, 0.1632, 0, 0.1712, 0.0627, 0.1453, 0.0211, 0.0547, 0.0258,
               0.0403, 0.0069, 0.0226]


def cost_vector(n, k):
    if k == 0:
        return np.array([0.0] + [1.0] * (n - 1))
    return np.array([k * i + 1.0 for i in range(n)])


def constraints(modes, tp, n, order, bounds):
    """A_eq, b_eq, A_ub, b_ub of the LP exactly as catalog C6.3/C6.4 prints them (unscaled)."""
    t = tp * np.arange(n)
    a_eq = [np.ones(n)]
    b_eq = [1.0]
    for w, z in modes:
        wd = w * math.sqrt(1 - z * z)
        growth = np.exp(z * w * t)
        for l in range(order + 1):
            a_eq.append(t**l * growth * np.cos(wd * t))
            a_eq.append(t**l * growth * np.sin(wd * t))
            b_eq += [0.0, 0.0]
    a_ub, b_ub = [], []
    tn = t[-1]
    for w, z, smax in bounds:
        wd = w * math.sqrt(1 - z * z)
        growth = np.exp(z * w * t)
        limit = smax * math.exp(tn * z * w) / math.sqrt(2)
        for row in (growth * np.cos(wd * t), growth * np.sin(wd * t)):
            a_ub += [row, -row]
            b_ub += [limit, limit]
    return (np.array(a_eq), np.array(b_eq), np.array(a_ub) if a_ub else None,
            np.array(b_ub) if b_ub else None)


def solve(modes, tp, n, order=0, bounds=(), k=1.0, ub=1.0):
    a_eq, b_eq, a_ub, b_ub = constraints(modes, tp, n, order, bounds)
    c = cost_vector(n, k)
    res = linprog(c, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=b_eq, bounds=[(0.0, ub)] * n, method="highs")
    return res


def feasible(modes, tp, n, order=0, bounds=()):
    return solve(modes, tp, n, order, bounds).status == 0


def min_pulse_count(modes, tp, order=0, bounds=(), n_cap=None):
    """Smallest feasible n <= n_cap (None when even n_cap is infeasible). Feasibility is monotone in
    n (appending a zero pulse keeps every constraint: the equalities do not change, the bound
    limits only grow with t_n), so bisection is exact; the answer is confirmed by solving at n and
    n - 1 explicitly."""
    if n_cap is None:
        n_cap = max_pulse_count(modes, tp, order)
    if not feasible(modes, tp, n_cap, order, bounds):
        return None
    lo, hi = 0, n_cap  # lo infeasible (n = 0 pulses), hi feasible
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if feasible(modes, tp, mid, order, bounds):
            hi = mid
        else:
            lo = mid
    assert hi == 1 or not feasible(modes, tp, hi - 1, order, bounds)
    return hi


def max_pulse_count(modes, tp, order):
    """The search cap of lp_shaper_search's default: durations up to twice that of the convolution
    of per-mode ZV^(d+1) shapers, sum_k (d + 1) pi / w_dk (E21's 10.979 s for the E22 modes)."""
    convolution = sum((order + 1) * math.pi / (w * math.sqrt(1 - z * z)) for w, z in modes)
    return int(math.floor(2.0 * convolution / tp + 1e-9)) + 1


def optimal_face(modes, tp, n, order, bounds, k, optimum):
    """[min, max] of every A_i over {feasible A with cost <= optimum + 1e-9}."""
    a_eq, b_eq, a_ub, b_ub = constraints(modes, tp, n, order, bounds)
    c = cost_vector(n, k)
    a_ub = np.vstack([a_ub, c]) if a_ub is not None else c.reshape(1, -1)
    b_ub = np.append(b_ub if b_ub is not None else [], optimum + 1e-9)
    lows, highs = [], []
    for i in range(n):
        e = np.zeros(n)
        e[i] = 1.0
        lo = linprog(e, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=b_eq, bounds=[(0, 1)] * n, method="highs")
        hi = linprog(-e, A_ub=a_ub, b_ub=b_ub, A_eq=a_eq, b_eq=b_eq, bounds=[(0, 1)] * n, method="highs")
        lows.append(lo.x[i])
        highs.append(hi.x[i])
    return lows, highs


def residual(times, amps, w, z, t_end=None):
    """V(w, z) of C6.3; t_end defaults to the last time."""
    times = np.asarray(times, float)
    amps = np.asarray(amps, float)
    wd = w * math.sqrt(1 - z * z)
    end = times[-1] if t_end is None else t_end
    return abs(np.sum(amps * np.exp(-z * w * (end - times)) * np.exp(1j * wd * times))) / amps.sum()


def bound_points(modes, ratios, smax):
    return [(r * w, z, smax) for w, z in modes for r in ratios]


def case(name, modes, tp, n, order, bounds, k, source):
    res = solve(modes, tp, n, order, bounds, k)
    assert res.status == 0, (name, res.message)
    lows, highs = optimal_face(modes, tp, n, order, bounds, k, res.fun)
    times = list(tp * np.arange(n))
    return {
        "name": name,
        "source": source,
        "modes": [[w, z] for w, z in modes],
        "tp": tp,
        "n": n,
        "derivative_order": order,
        "bounds": [list(b) for b in bounds],
        "cost_k": k,
        "amplitudes": list(res.x),
        "cost": res.fun,
        "amplitude_min": lows,
        "amplitude_max": highs,
        "unique": bool(max(h - l for l, h in zip(lows, highs)) < 1e-7),
        "residual_at_modes": [residual(times, res.x, w, z) for w, z in modes],
    }


def search(modes, order, bounds, sample_period, max_tp):
    rows = []
    j = 1
    while j * sample_period <= max_tp * (1 + 1e-12):
        tp = j * sample_period
        n = min_pulse_count(modes, tp, order, bounds)
        if n is not None:
            res = solve(modes, tp, n, order, bounds, 1.0)
            rows.append({"multiple": j, "tp": tp, "n": n, "tf": (n - 1) * tp, "cost": res.fun})
        j += 1
    return rows


def main():
    e23_bounds = bound_points(E_MODES, (0.85, 1.15), 0.05)
    cases = [
        case("e22", E_MODES, 0.68, 14, 1, [], 1.0, "catalog E22 (eq. 6.78): ZV + first derivative, J2 k = 1"),
        case("e23", E_MODES, 0.63, 14, 0, e23_bounds, 1.0,
             "catalog E23 (eq. 6.79): ZV + S <= 5 % at 0.85 / 1.15 x each mode, J2 k = 1"),
        case("e22_j1", E_MODES, 0.68, 16, 1, [], 0.0, "E22 constraints with J1 (maximize A_1), n = 16"),
        case("two_modes_d2", [(5.0, 0.02), (13.0, 0.05)], 0.1, 24, 2, [], 2.0,
             "two modes, ZV + first + second derivative, J2 k = 2"),
        case("single_zv", [(2.0, 0.0)], math.pi / 2.0, 2, 0, [], 1.0,
             "one undamped mode, Tp = half period: the two-pulse ZV [0.5, 0.5]"),
    ]

    e22_min_n = []
    for tp in (0.63, 0.68, 0.75):
        n = min_pulse_count(E_MODES, tp, 1)
        e22_min_n.append({"tp": tp, "n": n, "tf": (n - 1) * tp})

    # The printed E22 / E23 amplitudes against the constraints (printed to 4 decimals, so the
    # equalities hold to ~1e-4 only).
    printed = {}
    for name, amps, tp, order, bounds in (("e22", E22_PRINTED, 0.68, 1, []), ("e23", E23_PRINTED, 0.63, 0, e23_bounds)):
        a = np.array(amps)
        a_eq, b_eq, a_ub, b_ub = constraints(E_MODES, tp, len(a), order, bounds)
        tn = tp * (len(a) - 1)
        scale = np.array([1.0] + [math.exp(-z * w * tn) for w, z in E_MODES for _ in range(2 * (order + 1))])
        printed[name] = {
            "amplitudes": amps,
            "cost_j2_k1": float(cost_vector(len(a), 1.0) @ a),
            "sum": float(a.sum()),
            "max_scaled_equality_violation": float(np.max(np.abs((a_eq @ a - b_eq) * scale))),
            "sensitivities": [residual(tp * np.arange(len(a)), a, w, z, tn) for w, z, _ in bounds],
        }

    # E23's print is not exactly zero-vibration: replacing the ZV equalities by V <= 0.1 % at each
    # mode (4 inequalities each) reproduces it closely.
    relaxed_bounds = e23_bounds + [(w, z, 0.001) for w, z in E_MODES]
    a_eq, b_eq, a_ub, b_ub = constraints(E_MODES, 0.63, 14, 0, relaxed_bounds)
    relaxed = linprog(cost_vector(14, 1.0), A_ub=a_ub, b_ub=b_ub, A_eq=a_eq[:1], b_eq=b_eq[:1],
                      bounds=[(0.0, 1.0)] * 14, method="highs")
    printed_e23 = np.array(E23_PRINTED) / sum(E23_PRINTED)
    printed["e23"]["relaxed_zv_0p1"] = {
        "amplitudes": list(relaxed.x),
        "cost": relaxed.fun,
        "max_abs_difference_to_print": float(np.max(np.abs(relaxed.x - printed_e23))),
    }

    sample_period = 0.05
    max_tp = math.pi / min(w * math.sqrt(1 - z * z) for w, z in E_MODES)
    doc = {
        "generator": "tools/reference/shaping_lp_reference.py (scipy.optimize.linprog, HiGHS)",
        "cases": cases,
        "e22_min_n": e22_min_n,
        "printed": printed,
        "search_e22": {
            "sample_period": sample_period,
            "max_tp": max_tp,
            "derivative_order": 1,
            "rows": search(E_MODES, 1, [], sample_period, max_tp),
        },
    }
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print("wrote", OUT)


if __name__ == "__main__":
    main()
