#!/usr/bin/env python3
"""Plain numpy/scipy implementation of `servotwin identify` for speed comparison.

Same pipeline as the C++ tool: read the capture CSV, build the thesis's regressors (Eq. 3.9-3.11:
e_i, -xdot, -xddot, x_r, xdot_r, xddot_r, -PV, -NV with central differences), least squares, and
the bounded problem over (p, wn, zeta) with the linear parameters eliminated (Eq. 4.9), solved by
multi-start L-BFGS-B (scipy has no certified global solver; this is what a careful engineer would
write). Prints the model and the time of each stage as JSON.

    /usr/bin/python3 bench/reference/identify_reference.py capture.csv --axis x [--map x_cmd=qg ...] [--scale 1000]
"""
import argparse
import json
import time

import numpy as np
from scipy.optimize import minimize


def read_capture(path, axis, mapping, scale):
    with open(path) as f:
        header, header_line = None, 0
        for header_line, line in enumerate(f):
            if line.strip() and not line.lstrip().startswith("#"):
                header = [h.strip() for h in line.split(",")]
                break
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=header_line + 1, ndmin=2)
    col = {name: i for i, name in enumerate(header)}

    def column(ours):
        return data[:, col[mapping.get(ours, ours)]]

    t = column("t")
    ts = (t[-1] - t[0]) / (len(t) - 1)
    return column(axis + "_cmd") * scale, column(axis + "_act") * scale, ts


def regressors(xr, x, ts, deadband=None):
    def d1(v):
        return (v[2:] - v[:-2]) / (2 * ts)

    xd = d1(x)  # index k = 1 .. n-2
    xdd = d1(xd)  # index k = 2 .. n-3
    xrd = d1(xr)
    xrdd = d1(xrd)
    ei = ts * np.cumsum(xr - x)
    k = slice(2, len(x) - 2)
    v = xd[1:-1]
    if deadband is None:
        steps = np.abs(np.diff(x))
        q = steps[steps > 0].min() if np.any(steps > 0) else 0.0
        deadband = 1.5 * q / ts
    pv = (v > deadband).astype(float)
    nv = (v < -deadband).astype(float)
    phi = np.column_stack([ei[k], -v, -xdd, xr[k], xrd[1:-1], xrdd, -pv, -nv])
    return phi, x[k]


def theta1(p, wn, zeta):
    a1 = p + 2 * zeta * wn
    a2 = wn * wn + 2 * p * zeta * wn
    a3 = p * wn * wn
    return np.array([a3 / a2, a1 / a2, 1.0 / a2])


def solve_bounded(P, R, G, bounds, starts=20, seed=1):
    P22inv_P21 = np.linalg.solve(P[3:, 3:], P[3:, :3])
    P22inv_R2 = np.linalg.solve(P[3:, 3:], R[3:])
    S = P[:3, :3] - P[:3, 3:] @ P22inv_P21
    r = R[:3] - P[:3, 3:] @ P22inv_R2
    g = G - R[3:] @ P22inv_R2

    def f(v):
        th = theta1(np.exp(v[0]), np.exp(v[1]), v[2])
        return 0.5 * (th @ S @ th - 2 * r @ th + g)

    lo = [np.log(bounds["p"][0]), np.log(bounds["wn"][0]), bounds["zeta"][0]]
    hi = [np.log(bounds["p"][1]), np.log(bounds["wn"][1]), bounds["zeta"][1]]
    rng = np.random.default_rng(seed)
    best = None
    for _ in range(starts):
        v0 = rng.uniform(lo, hi)
        res = minimize(f, v0, method="L-BFGS-B", bounds=list(zip(lo, hi)))
        if best is None or res.fun < best.fun:
            best = res
    p, wn, zeta = np.exp(best.x[0]), np.exp(best.x[1]), best.x[2]
    th1 = theta1(p, wn, zeta)
    th2 = P22inv_R2 - P22inv_P21 @ th1
    return np.concatenate([th1, th2]), best.fun, (p, wn, zeta)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("capture")
    ap.add_argument("--axis", default="x")
    ap.add_argument("--map", action="append", default=[])
    ap.add_argument("--scale", type=float, default=1.0)
    args = ap.parse_args()
    mapping = dict(m.split("=", 1) for m in args.map)
    t0 = time.perf_counter()
    xr, x, ts = read_capture(args.capture, args.axis, mapping, args.scale)
    t1 = time.perf_counter()
    phi, y = regressors(xr, x, ts)
    P, R, G = phi.T @ phi, phi.T @ y, y @ y
    t2 = time.perf_counter()
    theta_ls = np.linalg.lstsq(phi, y, rcond=None)[0]
    t3 = time.perf_counter()
    nyq = np.pi / ts
    bounds = {"p": (2 * np.pi * 0.2, nyq), "wn": (2 * np.pi * 0.2, nyq), "zeta": (0.2, 2.0)}
    theta, fval, (p, wn, zeta) = solve_bounded(P, R, G, bounds)
    t4 = time.perf_counter()
    a2 = 1 / theta[2]
    print(json.dumps({
        "samples": len(x), "ts": ts,
        "model": {"a1": theta[1] * a2, "a2": a2, "a3": theta[0] * a2, "b0": theta[5] * a2, "b1": theta[4] * a2,
                  "b2": theta[3] * a2, "d0": theta[6] * a2, "d1": theta[7] * a2},
        "search": {"p_hz": p / (2 * np.pi), "wn_hz": wn / (2 * np.pi), "zeta": zeta}, "objective": fval,
        "ls_a2": 1 / theta_ls[2],
        "time_ms": {"read": 1e3 * (t1 - t0), "regressors_and_statistics": 1e3 * (t2 - t1), "ls": 1e3 * (t3 - t2),
                    "bounded": 1e3 * (t4 - t3), "total": 1e3 * (t4 - t0)}}, indent=1))


if __name__ == "__main__":
    main()
