#!/usr/bin/env python3
"""Reference values for the controller-tuning foundation (module `tuning`, issue 7 increment 2).

Writes tests/data/tuning/tuning_reference.json. Every number is computed here independently of
the C++ code, with a different formulation wherever the C++ side has a choice:

  * PI partial pole placement: the C++ code takes the remainder of c(s) modulo the assigned
    quadratic; here c(s1) is evaluated at the complex pole s1 = w*(-z* + j sqrt(1 - z*^2)) and its
    real/imaginary parts solved with numpy.linalg.solve (for z* = 1: c(-w*) = 0 and c'(-w*) = 0,
    as catalog C7.3 states it). For z* > 1: c at both real roots.
  * Closed-loop poles and the "second pair": numpy.roots of the closed-loop polynomial, then the
    two roots nearest the assigned pair removed (the C++ code divides c(s) by the pair instead).
  * Admissible range: a dense log grid (4001 points) of the boolean test "Kp > 0, Ki > 0, all roots
    in the open left half-plane, second pair's smallest root modulus >= w*" and 80 bisection steps
    on each boundary (the C++ code uses Routh-Hurwitz and an algebraic second pair).
  * C7.4 tables: xi2max by scipy.optimize.minimize_scalar (bounded) on the grid maximum's
    neighbourhood, w*max by the admissible-range routine above on the undamped plant.
  * Two-mass parameters with friction (E-fric): scipy.optimize.fsolve on the five coefficient
    equations of C3.12 (Im = 1), not the closed-form quadratic of the plan (section 1.1).
  * E24: the symmetric optimum and rigid pole placement (closed formulas of catalog C7.1) and
    numpy.roots of the loops with the tau_f = 0.01 feedback filter.

  * Robustness (C7.9, key "robustness"): interval closed loop by numpy.polymul of the transfer
    function, Kharitonov polynomials rooted with numpy.roots, the 5^6 grid by batched companion
    eigenvalues (numpy.linalg.eigvals), the largest robust w* by the method of robustness.hpp with
    this script's admissible range and root-based stability (the C++ code uses Routh signs).

Sources of the examples: catalog seed2_catalog.md E24, E25, E26, C7.4, E28 (gains and the Kharitonov
margins of k3), A5; issue-7 plan section 2 rows E-PID and E-fric.

Run:  /usr/bin/python3 tools/reference/tuning_reference.py   (numpy, scipy)
"""
import json
import math
import os

import numpy as np
from scipy import optimize

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "tuning", "tuning_reference.json")
SQRT_HALF = math.sqrt(0.5)


# ----------------------------------------------------------------------------- plants
def two_mass(r, zeta_z, zeta_p=None, a=0.0):
    """Normalized design plant N/Dp (catalog C7.6); zeta_p defaults to the frictionless r*zeta_z."""
    if zeta_p is None:
        zeta_p = r * zeta_z
    num = np.array([1.0, 2.0 * zeta_z, 1.0])
    rigid = np.array([1.0, a]) if a > 0 else np.array([1.0, 0.0])
    den = np.polymul(rigid, [1.0, 2.0 * zeta_p * r, r * r])
    return num, den


def closed_loop(num, den, kp, ki, kd=0.0, tau=0.0, filt=0.0):
    """c(s) = s Dp (tau s + 1)(filt s + 1) + [(kp s + ki)(tau s + 1) + kd s^2] N (filter in the feedback)."""
    ctrl = np.polyadd(np.polymul([kp, ki], [tau, 1.0]), [kd, 0.0, 0.0])
    plant_part = np.polymul(np.polymul([1.0, 0.0], den), np.polymul([tau, 1.0], [filt, 1.0]))
    return np.polyadd(plant_part, np.polymul(ctrl, num))


def place(num, den, w, z, kd=0.0, tau=0.0):
    """(Kp, Ki) with c(s) = 0 on the pair s^2 + 2 z w s + w^2, by evaluation at its roots."""
    c0 = np.polyadd(np.polymul(np.polymul([1.0, 0.0], den), [tau, 1.0]), np.polymul([kd, 0.0, 0.0], num))
    cp = np.polymul(np.polymul([1.0, 0.0], [tau, 1.0]), num)
    ci = np.polymul([tau, 1.0], num)
    if z < 1.0:
        s1 = w * complex(-z, math.sqrt(1.0 - z * z))
        vp, vi, v0 = np.polyval(cp, s1), np.polyval(ci, s1), np.polyval(c0, s1)
        a = np.array([[vp.real, vi.real], [vp.imag, vi.imag]])
        b = -np.array([v0.real, v0.imag])
    elif z == 1.0:
        s1 = -w
        a = np.array([[np.polyval(cp, s1), np.polyval(ci, s1)],
                      [np.polyval(np.polyder(cp), s1), np.polyval(np.polyder(ci), s1)]])
        b = -np.array([np.polyval(c0, s1), np.polyval(np.polyder(c0), s1)])
    else:
        p1, p2 = w * (-z + math.sqrt(z * z - 1.0)), w * (-z - math.sqrt(z * z - 1.0))
        a = np.array([[np.polyval(cp, p1), np.polyval(ci, p1)], [np.polyval(cp, p2), np.polyval(ci, p2)]])
        b = -np.array([np.polyval(c0, p1), np.polyval(c0, p2)])
    kp, ki = np.linalg.solve(a, b)
    return float(kp), float(ki)


def split_roots(c, w, z):
    """Roots of c sorted; the two nearest the assigned pair removed -> (assigned, rest)."""
    roots = list(np.roots(c))
    if z < 1.0:
        targets = [w * complex(-z, math.sqrt(1 - z * z)), w * complex(-z, -math.sqrt(1 - z * z))]
    else:
        targets = [w * (-z + math.sqrt(z * z - 1.0)), w * (-z - math.sqrt(z * z - 1.0))]
    assigned = []
    for t in targets:
        k = int(np.argmin([abs(x - t) for x in roots]))
        assigned.append(roots.pop(k))
    rest = sorted(roots, key=lambda x: (abs(x), x.real, -x.imag))
    return assigned, rest


def pairs(roots):
    return [[float(x.real), float(x.imag)] for x in roots]


# ----------------------------------------------------------------------------- closed forms (oracles)
def closed_form_damped(w, xs, r, xz):
    """Eq. 7.63 (catalog C7.3); xz = 0 is eq. 7.36."""
    nump = (2 * xs * w**5 + (2 * xz * (1 - r * r) - 8 * xz * xs**2) * w**4
            + (8 * xs**3 + 8 * xz**2 * xs * r * r - 4 * xs) * w**3 - 8 * xs**2 * xz * r * r * w**2 + 2 * xs * r * r * w)
    numi = w**2 * (w**4 - 4 * xs * xz * w**3 + (4 * xz**2 * r * r - r * r + 4 * xs**2 - 1) * w**2
                   - 4 * xs * xz * r * r * w + r * r)
    den = w**4 - 4 * xs * xz * w**3 - (2 - 4 * xz**2 - 4 * xs**2) * w**2 - 4 * xs * xz * w + 1
    return nump / den, numi / den


# ----------------------------------------------------------------------------- admissible range
def verdict(num, den, w, z, kd=0.0, radius_tol=1e-9):
    """'ok' or the first failing condition at w* (same order as the C++ code: ki, kp, stability, radius)."""
    kp, ki = place(num, den, w, z, kd)
    if not ki > 0:
        return "ki"
    if not kp > 0:
        return "kp"
    c = closed_loop(num, den, kp, ki, kd)
    if not np.all(np.roots(c).real < 0):
        return "stability"
    _, rest = split_roots(c, w, z)
    if min(abs(x) for x in rest) < w * (1.0 - radius_tol):
        return "radius"
    return "ok"


def bisect_boundary(num, den, z, lo, hi, lo_ok, kd=0.0):
    """Boundary between lo and hi where the verdict changes; lo_ok says which end passes."""
    for _ in range(80):
        mid = math.sqrt(lo * hi)
        ok = verdict(num, den, mid, z, kd) == "ok"
        if ok == lo_ok:
            lo = mid
        else:
            hi = mid
    return lo, hi


def admissible_range(num, den, z, kd=0.0, upper=1.0, points=4001):
    grid = np.geomspace(1e-4 * upper, upper, points)
    # At w* = 1 the radius equals w* whenever r <= sqrt(4 z* + 1), and for r = sqrt(3), z* = sqrt(1/2)
    # the two pairs coincide there: numpy.roots then loses half the digits, hence 1e-7 at that point.
    v = [verdict(num, den, w, z, kd, 1e-7 if w == upper else 1e-9) for w in grid]
    ok = [x == "ok" for x in v]
    first = ok.index(True)
    last = first
    while last + 1 < len(grid) and ok[last + 1]:
        last += 1
    w_min = 0.0
    lower = "none"
    if first > 0:
        a, b = bisect_boundary(num, den, z, grid[first - 1], grid[first], False, kd)
        w_min = b
        lower = v[first - 1]
    if last == len(grid) - 1:
        return {"omega_min": w_min, "omega_max": upper, "lower": lower, "upper": "full"}
    a, b = bisect_boundary(num, den, z, grid[last], grid[last + 1], True, kd)
    return {"omega_min": w_min, "omega_max": a, "lower": lower, "upper": v[last + 1]}


def second_pair_damping(num, den, w, z):
    kp, ki = place(num, den, w, z)
    c = closed_loop(num, den, kp, ki)
    _, rest = split_roots(c, w, z)
    q = np.real(np.poly(rest))
    return q[1] / (2.0 * math.sqrt(q[2]))


def xi2_max(r, z):
    num, den = two_mass(r, 0.0)
    grid = np.linspace(1e-3, 1.0, 2001)
    vals = [second_pair_damping(num, den, w, z) for w in grid]
    k = int(np.argmax(vals))
    if k == len(grid) - 1:
        return float(vals[-1]), 1.0
    res = optimize.minimize_scalar(lambda w: -second_pair_damping(num, den, w, z),
                                   bounds=(grid[max(k - 1, 0)], grid[k + 1]), method="bounded",
                                   options={"xatol": 1e-12})
    return float(-res.fun), float(res.x)


# ----------------------------------------------------------------------------- examples
def e24():
    im, il, b, k, tf = 1.0, 8.0, 0.2, 8.0, 0.01
    j = im + il
    so = {"kp": j / (2 * tf), "ki": j / (8 * tf * tf)}
    # Motor TF of the two-mass plant (C3.12 frictionless): (Il s^2 + b s + k)/(s (Im Il s^2 + b J s + k J)).
    num = np.array([il, b, k])
    den = np.array([im * il, b * j, k * j, 0.0])
    num, den = num / den[0], den / den[0]
    rows = []
    for name, kp, ki in [("so", so["kp"], so["ki"])] + [
            (f"pp_{w}", 2 * 0.8 * w * j, j * w * w) for w in (0.3, 0.6, 2.0)]:
        c = closed_loop(num, den, kp, ki, filt=tf)
        roots = np.roots(c)
        zetas = [-x.real / abs(x) for x in roots]
        kmin = int(np.argmin(zetas))
        rows.append({"name": name, "kp": kp, "ki": ki, "min_zeta": float(zetas[kmin]),
                     "min_zeta_root": [float(roots[kmin].real), float(abs(roots[kmin].imag))]})
    return {"plant": {"motor_inertia": im, "load_inertia": il, "damping": b, "stiffness": k, "filter_s": tf,
                      "num": list(num), "den": list(den)},
            "so": so, "loops": rows}


def e25():
    out = []
    for r in (1.2, 2.0, 4.0):
        num, den = two_mass(r, 0.0)
        kp, ki = place(num, den, 0.5, SQRT_HALF)
        cfp, cfi = closed_form_damped(0.5, SQRT_HALF, r, 0.0)
        _, rest = split_roots(closed_loop(num, den, kp, ki), 0.5, SQRT_HALF)
        out.append({"r": r, "kp": kp, "ki": ki, "kp_closed_form": cfp, "ki_closed_form": cfi,
                    "second_pair": pairs(rest)})
    return out


def c74_tables():
    rs = [1.2, 1.5, math.sqrt(3), 2.0, math.sqrt(5), 2.5, 3.0, 4.0, 5.0, 8.0]
    out = []
    for z in (SQRT_HALF, 1.0):
        for r in rs:
            num, den = two_mass(r, 0.0)
            x2, at = xi2_max(r, z)
            rng = admissible_range(num, den, z)
            out.append({"zeta_star": z, "r": r, "xi2_max": x2, "xi2_max_at": at,
                        "omega_max": rng["omega_max"], "limited_by": rng["upper"]})
    return out


def e26():
    num, den = two_mass(3.0, 0.01)
    out = {"cases": []}
    for w, z in ((0.30, 1.0), (0.67, 1.0), (0.5, 0.8), (0.9, SQRT_HALF)):
        kp, ki = place(num, den, w, z)
        cfp, cfi = closed_form_damped(w, z, 3.0, 0.01)
        assigned, rest = split_roots(closed_loop(num, den, kp, ki), w, z)
        out["cases"].append({"omega_star": w, "zeta_star": z, "kp": kp, "ki": ki, "kp_closed_form": cfp,
                             "ki_closed_form": cfi, "second_pair": pairs(rest)})
    printed = np.roots(closed_loop(num, den, 4.63, 0.64))
    out["printed_gains_poles"] = pairs(sorted(printed, key=lambda x: (abs(x), -x.imag)))
    out["admissible"] = {str(z): admissible_range(num, den, z) for z in (SQRT_HALF, 0.8, 1.0)}
    return out


def gain_root_cases():
    """Damped frictionless plants whose Ki numerator of eq. 7.63 has a root in (0, 1] (numpy.roots)."""
    out = []
    for r, zz, zs in ((2.0, 0.2, 0.5), (3.0, 0.2, 1.0), (5.0, 0.1, SQRT_HALF), (1.5, 0.1, 0.2)):
        r2 = r * r
        nump = [2 * zs, 2 * zz * (1 - r2) - 8 * zz * zs * zs, 8 * zs**3 + 8 * zz * zz * zs * r2 - 4 * zs,
                -8 * zs * zs * zz * r2, 2 * zs * r2]
        numi = [1, -4 * zs * zz, 4 * zz * zz * r2 - r2 + 4 * zs * zs - 1, -4 * zs * zz * r2, r2]
        real_roots = [x.real for x in np.concatenate([np.roots(nump), np.roots(numi)])
                      if abs(x.imag) < 1e-12 and 0 < x.real <= 1]
        num, den = two_mass(r, zz)
        out.append({"r": r, "zeta_z": zz, "zeta_star": zs, "gain_limit": min(real_roots) if real_roots else 1.0,
                    "admissible": admissible_range(num, den, zs)})
    return out


def e_pid():
    r, rbar = 4.0, 2.0
    kd = (r * r - 1) / (rbar * rbar - 1) - 1
    num, den = two_mass(r, 0.0)
    kbp, kbi = place(*two_mass(rbar, 0.0), 0.5, SQRT_HALF)
    kp, ki = place(num, den, 0.5, SQRT_HALF, kd=kd)
    ideal = np.roots(closed_loop(num, den, kp, ki, kd=kd))
    tau = 0.01
    kpt, kit = place(num, den, 0.5, SQRT_HALF, kd=kd, tau=tau)
    filtered = np.roots(closed_loop(num, den, kpt, kit, kd=kd, tau=tau))
    # Gains of the ideal design with the filter simply added (the plan's "within 3 %" statement).
    added = np.roots(closed_loop(num, den, kp, ki, kd=kd, tau=tau))
    key = lambda x: (abs(x), -x.imag)
    return {"r": r, "r_target": rbar, "kd": kd, "pi_virtual": [kbp, kbi], "kp": kp, "ki": ki,
            "poles_ideal": pairs(sorted(ideal, key=key)), "tau": tau, "kp_tau": kpt, "ki_tau": kit,
            "poles_tau": pairs(sorted(filtered, key=key)), "poles_ideal_gains_with_tau": pairs(sorted(added, key=key))}


def e_fric():
    """Table 5.1 normalized: solve the C3.12 coefficient equations (Im = 1) with fsolve."""
    r, zz, zp, a = 3.0, 0.06, 0.15, 0.2
    num, den = two_mass(r, zz, zp, a)  # den = (s + a)(s^2 + 2 zp r s + r^2)

    def eqs(x):
        il, k, b, bm, bl = x
        # (Il s^2 + (b + bl) s + k) / Q, Q = Il s^3 + (bl + bm Il + b(1 + Il)) s^2 + (bm bl + k(1 + Il) + b(bm + bl)) s + k(bm + bl)
        return [k / il - num[2], (b + bl) / il - num[1],
                (bl + bm * il + b * (1 + il)) / il - den[1],
                (bm * bl + k * (1 + il) + b * (bm + bl)) / il - den[2],
                k * (bm + bl) / il - den[3]]

    sol = optimize.fsolve(eqs, [8.0, 8.0, 0.1, 0.9, 0.9], xtol=1e-14)
    il, k, b, bm, bl = sol
    ranges = {str(z): admissible_range(num, den, z) for z in (SQRT_HALF, 0.8, 1.0)}
    return {"r": r, "zeta_z": zz, "zeta_p": zp, "a": a, "load_inertia": il, "stiffness": k, "damping": b,
            "motor_viscous": bm, "load_viscous": bl, "residual": float(np.max(np.abs(eqs(sol)))),
            "admissible": ranges}


def e28():
    """E28 plant (K = 1, a = 0.1, xi = 0.02, xi_z = 0.01, w = 2, wz = 1), w* = 0.9: the nominal gains."""
    num, den = two_mass(2.0, 0.01, 0.02, 0.1)
    out = []
    for z in (SQRT_HALF, 1.0):
        kp, ki = place(num, den, 0.9, z)
        _, rest = split_roots(closed_loop(num, den, kp, ki), 0.9, z)
        out.append({"zeta_star": z, "kp": kp, "ki": ki, "second_pair": pairs(rest)})
    return {"cases": out, "admissible": {str(z): admissible_range(num, den, z) for z in (SQRT_HALF, 1.0)}}


def generic():
    """A three-mode plant with a lag (no closed form): numeric PI and PID pole placement only."""
    num = np.polymul(np.polymul([1.0, 0.02, 1.0], [1.0, 0.3, 25.0]), [1.0, 0.8, 144.0])
    den = np.polymul(np.polymul(np.polymul([1.0, 0.05], [1.0, 0.12, 4.0]), [1.0, 0.6, 49.0]),
                     np.polymul([1.0, 1.5, 225.0], [1.0, 40.0]))
    gain = 40.0 * 4.0 * 49.0 * 225.0 / (25.0 * 144.0)  # unit HF asymptote of the first-mode part
    num = gain * num
    cases = []
    for w, z, kd, tau in ((0.4, 0.8, 0.0, 0.0), (0.6, 1.0, 0.0, 0.0), (0.5, 1.3, 0.0, 0.0),
                          (0.5, SQRT_HALF, 1.5, 0.02)):
        kp, ki = place(num, den, w, z, kd, tau)
        cases.append({"omega_star": w, "zeta_star": z, "kd": kd, "tau": tau, "kp": kp, "ki": ki})
    return {"num": list(num), "den": list(den), "cases": cases}


def a5():
    r = 12.1 / 4.5
    return {"r": r, "kd": (r * r - 1) / (2.0 * 2.0 - 1) - 1}


# ----------------------------------------------------------------------------- robustness (C7.9)
# Interval plant K(s^2 + 2 xi_z wz s + wz^2)/((s + a)(s^2 + 2 xi w s + w^2)) under PI. Here the
# closed loop is expanded with numpy.polymul/polyadd from the transfer function (the C++ side uses
# the coefficient formulas), stability is max Re(numpy roots / companion eigenvalues) < 0 (the C++
# side uses Routh signs), and the design is the numpy c(s1) evaluation of place() above.
PARAMS = ("k", "a", "xi", "xi_z", "omega", "omega_z")


def interval_box(nominal, spread):
    return {n: (nominal[n] * (1.0 - spread[n]), nominal[n] * (1.0 + spread[n])) for n in PARAMS}


def interval_closed_loop(p, kp, ki):
    num = p["k"] * np.array([1.0, 2.0 * p["xi_z"] * p["omega_z"], p["omega_z"] ** 2])
    den = np.polymul([1.0, p["a"]], [1.0, 2.0 * p["xi"] * p["omega"], p["omega"] ** 2])
    return np.polyadd(np.polymul([1.0, 0.0], den), np.polymul([kp, ki], num))


def nominal_design(nominal, w, z):
    """Physical gains from the normalized design: Kp = Kp_n Im wz, Ki = Ki_n Im wz^2, Im = 1/K."""
    wz = nominal["omega_z"]
    num, den = two_mass(nominal["omega"] / wz, nominal["xi_z"], nominal["xi"], nominal["a"] / wz)
    kp, ki = place(num, den, w / wz, z)
    return kp * wz / nominal["k"], ki * wz * wz / nominal["k"]


def kharitonov_ref(box, kp, ki):
    lo = interval_closed_loop({n: box[n][0] for n in PARAMS}, kp, ki)[::-1]  # a0 .. a4
    hi = interval_closed_loop({n: box[n][1] for n in PARAMS}, kp, ki)[::-1]
    polys = [[1.0, hi[3], hi[2], lo[1], lo[0]], [1.0, lo[3], lo[2], hi[1], hi[0]],
             [1.0, hi[3], lo[2], lo[1], hi[0]], [1.0, lo[3], hi[2], hi[1], lo[0]]]
    max_re = [float(max(np.roots(q).real)) for q in polys]
    return {"lower": [float(x) for x in lo[:4]], "upper": [float(x) for x in hi[:4]],
            "polynomials": [[float(x) for x in q] for q in polys], "max_real_part": max_re,
            "hurwitz": [m < 0.0 for m in max_re], "robust": all(m < 0.0 for m in max_re)}


def grid_ref(box, kp, ki, n=5):
    """All n^6 combinations (itertools order K, a, xi, xi_z, w, wz), batched companion eigenvalues."""
    import itertools
    values = [np.linspace(box[x][0], box[x][1], n) if box[x][0] != box[x][1] else np.array([box[x][0]])
              for x in PARAMS]
    pts = np.array(list(itertools.product(*values)))
    coeffs = np.array([interval_closed_loop(dict(zip(PARAMS, q)), kp, ki) for q in pts])
    comp = np.zeros((len(pts), 4, 4))
    comp[:, 0, :] = -coeffs[:, 1:] / coeffs[:, :1]
    comp[:, 1, 0] = comp[:, 2, 1] = comp[:, 3, 2] = 1.0
    alpha = np.linalg.eigvals(comp).real.max(axis=1)
    worst = int(np.argmax(alpha))
    fails = np.nonzero(alpha >= 0.0)[0]
    return {"cases": len(pts), "failures": int(len(fails)), "worst_max_real_part": float(alpha[worst]),
            "worst": [float(x) for x in pts[worst]],
            "first_failure": [float(x) for x in pts[fails[0]]] if len(fails) else None}


def robust_pass(box, kp, ki):
    return kharitonov_ref(box, kp, ki)["robust"] or grid_ref(box, kp, ki)["failures"] == 0


def largest_robust_omega_star_ref(nominal, box, z):
    """The method stated in robustness.hpp, with this script's admissible range and stability tests."""
    wz = nominal["omega_z"]
    num, den = two_mass(nominal["omega"] / wz, nominal["xi_z"], nominal["xi"], nominal["a"] / wz)
    rng = admissible_range(num, den, z)
    lo, hi = rng["omega_min"], rng["omega_max"]
    def passes(w):
        kp, ki = nominal_design(nominal, w * wz, z)
        return kp >= 0.0 and ki >= 0.0 and robust_pass(box, kp, ki)
    if passes(hi):
        return hi * wz
    fail = hi
    low = max(lo, 1e-3 * hi)
    for j in range(23, 0, -1):
        w = low * (hi / low) ** (j / 24)
        if not passes(w):
            fail = w
            continue
        ok = w
        while fail - ok > 1e-5 * hi:
            mid = 0.5 * (ok + fail)
            if passes(mid):
                ok = mid
            else:
                fail = mid
        return ok * wz
    return 0.0


def robustness():
    """E28 (catalog) boxes. 'catalog': +-10 %, w +-30 %, xi_z held at its nominal value: this is the
    box that reproduces the catalog's k3 margins (-6.0e-4 for xi* = sqrt(1/2), -0.022 for xi* = 1).
    'literal': xi_z +-10 % as well (the text's "+-10 % on all"): k3 then has a root at +6.4e-5, so
    Kharitonov fails while the grid passes. 'wide': +-50 % on everything: both fail."""
    nominal = {"k": 1.0, "a": 0.1, "xi": 0.02, "xi_z": 0.01, "omega": 2.0, "omega_z": 1.0}
    spreads = {"catalog": {"k": 0.1, "a": 0.1, "xi": 0.1, "xi_z": 0.0, "omega": 0.3, "omega_z": 0.1},
               "literal": {"k": 0.1, "a": 0.1, "xi": 0.1, "xi_z": 0.1, "omega": 0.3, "omega_z": 0.1},
               "wide": {n: 0.5 for n in PARAMS}}
    out = {"nominal": nominal, "spreads": spreads, "cases": []}
    for name, spread in spreads.items():
        box = interval_box(nominal, spread)
        for z in (SQRT_HALF, 1.0):
            kp, ki = nominal_design(nominal, 0.9, z)
            out["cases"].append({"box": name, "zeta_star": z, "omega_star": 0.9, "kp": kp, "ki": ki,
                                 "kharitonov": kharitonov_ref(box, kp, ki), "grid": grid_ref(box, kp, ki)})
    # Largest robust w*: 'w48' (w +-48 %, the rest +-10 %) reaches w < wz at its corners; the grid
    # then fails above w* ~ 0.1-0.2, so the search bisects. Also in time-scaled units (x 2 pi).
    w48 = dict(spreads["literal"], omega=0.48)
    out["largest"] = []
    for name, spread, scale in (("wide", spreads["wide"], 1.0), ("catalog", spreads["catalog"], 1.0),
                                ("w48", w48, 1.0), ("w48", w48, 2 * math.pi)):
        nom = dict(nominal)
        for n in ("a", "omega", "omega_z"):
            nom[n] *= scale
        nom["k"] *= scale  # P_c(s) = P(s / c) keeps the loop shape
        for z in (SQRT_HALF, 1.0):
            out["largest"].append({"box": name, "spread": spread, "nominal": nom, "zeta_star": z,
                                   "omega_star": largest_robust_omega_star_ref(nom, interval_box(nom, spread), z)})
    return out


def main():
    data = {"generator": "tools/reference/tuning_reference.py", "e24": e24(), "e25": e25(),
            "c74_tables": c74_tables(), "e26": e26(), "gain_root_cases": gain_root_cases(), "e_pid": e_pid(), "e_fric": e_fric(), "e28": e28(),
            "generic": generic(), "a5": a5(), "robustness": robustness()}
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
