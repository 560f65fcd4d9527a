#!/usr/bin/env python3
"""Reference values for the plant-model fit (module `fit`) and Levenberg-Marquardt (core).

Writes tests/data/fit/fit_reference.json with:
  * lm_exponential: y = A exp(-k t) + c with seeded Gaussian noise, solved by
    scipy.optimize.least_squares(method="lm"); covariance = inv(J^T J) * ||r||^2/(m - n).
  * lm_rosenbrock_bounded: Rosenbrock residuals with the bound x <= 0.5, solved by
    scipy.optimize.least_squares(method="trf") (closed form: x = 0.5, y = 0.25, cost = 0.125).
  * models: frequency responses of the catalog's plants (E10 / Table 5.1, E37 configurations 1
    and 2, as printed, with "tau" values as pole locations in rad/s per catalog defect 29)
    from scipy.signal.freqs on the expanded polynomials.
  * two_mass: a C3.12 two-mass plant from physical parameters (Im, Il, k, b), its polynomial
    transfer function and the modal parameters from numpy.roots.

Run:  python3 tools/reference/fit_reference.py   (numpy, scipy)
"""
import json
import os

import numpy as np
from scipy import optimize, signal

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "fit", "fit_reference.json")


def lm_exponential():
    rng = np.random.default_rng(20240607)
    t = np.linspace(0.0, 4.0, 40)
    a, k, c = 2.5, 1.3, 0.5
    y = a * np.exp(-k * t) + c + 0.05 * rng.standard_normal(t.size)

    def res(p):
        return p[0] * np.exp(-p[1] * t) + p[2] - y

    def jac(p):
        e = np.exp(-p[1] * t)
        return np.column_stack([e, -p[0] * t * e, np.ones_like(t)])

    x0 = np.array([1.0, 0.5, 0.0])
    sol = optimize.least_squares(res, x0, jac=jac, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    r = res(sol.x)
    j = jac(sol.x)
    sigma2 = r @ r / (t.size - 3)
    cov = np.linalg.inv(j.T @ j) * sigma2
    return {"t": t.tolist(), "y": y.tolist(), "initial": x0.tolist(), "solution": sol.x.tolist(),
            "cost": float(0.5 * r @ r), "sigma2": float(sigma2), "covariance": cov.tolist()}


def lm_rosenbrock_bounded():
    def res(p):
        return np.array([10.0 * (p[1] - p[0] ** 2), 1.0 - p[0]])

    sol = optimize.least_squares(res, [-1.2, 1.0], bounds=([-np.inf, -np.inf], [0.5, np.inf]), method="trf",
                                 xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return {"initial": [-1.2, 1.0], "upper": [0.5, None], "solution": sol.x.tolist(), "cost": float(sol.cost)}


def quad(w, z):
    return [1.0, 2.0 * z * w, w * w]


def model_case(name, k, rigid_pole, modes, lag=None, output="velocity"):
    num = np.array([k])
    den = np.array([1.0, rigid_pole])
    for (wz, zz, wp, zp) in modes:
        num = np.polymul(num, quad(wz, zz))
        den = np.polymul(den, quad(wp, zp))
    if lag is not None:
        den = np.polymul(den, [1.0, lag])
    if output == "position":
        den = np.polymul(den, [1.0, 0.0])
    w = np.logspace(-3, 3, 25)
    _, h = signal.freqs(num, den, worN=w)
    return {"name": name, "gain": k, "rigid_pole": rigid_pole,
            "modes": [{"wz": m[0], "zeta_z": m[1], "wp": m[2], "zeta_p": m[3]} for m in modes],
            "lag_pole": lag, "output": output, "numerator": num.tolist(), "denominator": den.tolist(),
            "omega": w.tolist(), "re": h.real.tolist(), "im": h.imag.tolist()}


def models():
    return [
        model_case("E10", 0.5, 0.2, [(1.0, 0.06, 3.0, 0.15)]),
        model_case("E37-1", 544.6, 0.16, [(35.3, 0.19, 70.8, 0.02), (114.6, 0.11, 260.1, 0.005)], lag=0.0038),
        model_case("E37-2", 454.5, 0.15, [(49.9, 0.24, 254.0, 0.02)], lag=0.0022),
        model_case("E10-position", 0.5, 0.2, [(1.0, 0.06, 3.0, 0.15)], output="position"),
    ]


def two_mass():
    im, il, k, b = 2.0e-3, 5.0e-3, 40.0, 0.01
    num = np.array([il, b, k])                          # C3.12: omega_m/T_m numerator
    den = np.array([im * il, b * (im + il), k * (im + il), 0.0])
    zeros = np.roots(num)
    poles = [p for p in np.roots(den) if abs(p) > 0]
    zpair = [z for z in zeros if z.imag > 0][0]
    ppair = [p for p in poles if p.imag > 0][0]
    gain = num[0] / den[0]
    w = np.logspace(np.log10(20.0), np.log10(800.0), 40)
    _, h = signal.freqs(num, den, worN=w)
    return {"motor_inertia": im, "load_inertia": il, "stiffness": k, "damping": b,
            "numerator": num.tolist(), "denominator": den.tolist(), "gain": float(gain),
            "wz": float(abs(zpair)), "zeta_z": float(-zpair.real / abs(zpair)),
            "wp": float(abs(ppair)), "zeta_p": float(-ppair.real / abs(ppair)),
            "omega": w.tolist(), "re": h.real.tolist(), "im": h.imag.tolist()}


def main():
    data = {"generator": "tools/reference/fit_reference.py", "lm_exponential": lm_exponential(),
            "lm_rosenbrock_bounded": lm_rosenbrock_bounded(), "models": models(), "two_mass": two_mass()}
    with open(OUT, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
