#!/usr/bin/env python3
"""Reference values for multiplicative-uncertainty robustness and the P position loop (module
`tuning`, issue 7: catalog C7.9 "unstructured multiplicative", C7.10; plan sections 1.7, 1.8 and
rows E27 / E27-Kpp).

Writes tests/data/tuning/robust_reference.json. Independent of the C++ code:

  * Loops are formed here from numpy polynomials: L = C(jw) P(jw) e^{-jwD} with P the normalized
    two-mass plant (catalog section 0) and C = kp + ki/s (1-DoF unless stated).
  * Peaks (||W2 T||, ||S/Ms||, sup |S/Ms| + |W2 T|) on a dense log grid of 200001 points over
    [1e-3, 1e3] refined with scipy.optimize.minimize_scalar (bounded, log w) around the grid maximum.
    (C++: a 600-point grid plus closed-loop pole frequencies and golden-section refinement.)
  * Position loop over the velocity loop (C7.10): phi_l/phi* = Kpp Tvl/(s + Kpp Tvn) with
    Tvl = Tvn (2 zz s + 1)/(s^2 + 2 zz s + 1) (frictionless load side written out here);
    largest Kpp of each criterion by scipy.optimize.brentq on the continuous peak functions
    (the C++ code scans and bisects booleans):
      nominal:  sup |phi_l/phi*| = 1 (J1 constraint, no overshoot),
      RS:       sup |W2 (T Spn + Tpn)| = 1 (derived from P = Pn(1 + Delta W2); the printed form
                W2 Tvn Spn - W2 Tpn is evaluated too),
      RP exact: sup_w max_{|Delta|=1} |Tp(Delta)| = 1 with Tp(Delta) = Kpp Tvn (1 + Delta W2) /
                (s + Kpp Tvn + Delta W2 (s Tvn + Kpp Tvn)), the max over Delta by sampling the unit
                circle (512 angles) and Nelder-Mead refinement (the C++ code uses the closed-form
                image disk of the Moebius map),
      RP sufficient (printed): min over the grid [1e-3, 1e3] of
                |jw + Kpp Tvn| - |W2 Tvn| |jw + Kpp| - Kpp (|Tvn| + |W2 Tvn|) >= 0, bisection on the
                boolean; this value is set by the grid's lower end (see position_loop.hpp).
  * Largest w* with uncertainty: the PI placement and the admissible range of
    tuning_reference.py (evaluation of c(s) at the pair, numpy.roots), brentq on rs(w*) - 1 and
    rp(w*) - 1 on the admissible range.

E27 (catalog): W2 = 2.6 s/(s + 15), PI (4.63, 0.64), r = 3, zeta_z = 0.01. The printed
||W2 Tvn|| = 0.68 holds for the nominal loop WITHOUT the delay D = 0.15: W2 is the envelope of
|e^{-jwD} - 1| (checked here), and with the delay inside T the value is 1.79. The printed Kpp
bounds (RS 2, nominal 0.3, RP 0.11) are not reproduced (misprint 26): the numbers stored here are
ours, not the printed ones.

Run:  /usr/bin/python3 tools/reference/tuning_robust_reference.py   (numpy, scipy)
"""
import json
import math
import os
import sys

import numpy as np
from scipy import optimize

sys.path.insert(0, os.path.dirname(__file__))
from tuning_reference import admissible_range, place, two_mass  # noqa: E402

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "tuning", "robust_reference.json")
GRID = np.logspace(-3.0, 3.0, 200001)


def tf(num, den):
    return lambda w: np.polyval(num, 1j * np.asarray(w)) / np.polyval(den, 1j * np.asarray(w))


def velocity_loop(num, den, kp, ki, delay=0.0, wp=1.0):
    """(S, T, Tvn) frequency functions of the PI loop on N/Dp with a torque-path delay."""
    plant = tf(num, den)

    def parts(w):
        w = np.asarray(w, dtype=float)
        s = 1j * w
        c = kp + ki / s
        r = wp * kp + ki / s
        p = plant(w) * np.exp(-s * delay)
        return c, r, p

    def sens(w):
        c, _, p = parts(w)
        return 1.0 / (1.0 + c * p)

    def comp(w):
        c, _, p = parts(w)
        return c * p / (1.0 + c * p)

    def track(w):
        c, r, p = parts(w)
        return r * p / (1.0 + c * p)

    return sens, comp, track


def sup(f, grid=GRID):
    """sup |f| on the grid, refined by minimize_scalar in log w around the best grid point."""
    v = np.abs(f(grid))
    i = int(np.argmax(v))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if hi <= lo:
        return float(v[i]), float(grid[i])
    res = optimize.minimize_scalar(lambda x: -abs(f(np.array([math.exp(x)]))[0]),
                                   bounds=(math.log(lo), math.log(hi)), method="bounded",
                                   options={"xatol": 1e-12})
    best = max(float(v[i]), -float(res.fun))
    return best, float(math.exp(res.x)) if -res.fun >= v[i] else float(grid[i])


def robustness(sens, comp, w2, ms):
    rs = sup(lambda w: w2(w) * comp(w))
    npf = sup(lambda w: sens(w) / ms)
    rp = sup(lambda w: np.abs(sens(w)) / ms + np.abs(w2(w) * comp(w)))
    return {"rs": rs[0], "rs_omega": rs[1], "np": npf[0], "np_omega": npf[1], "rp": rp[0], "rp_omega": rp[1]}


# ----------------------------------------------------------------------------- E27
def e27():
    r, zz = 3.0, 0.01
    num, den = two_mass(r, zz)
    kp, ki = 4.63, 0.64
    w2 = tf([2.6, 0.0], [1.0, 15.0])
    sens, comp, track = velocity_loop(num, den, kp, ki)
    _, comp_d, _ = velocity_loop(num, den, kp, ki, delay=0.15)
    out = {"kp": kp, "ki": ki, "r": r, "zeta_z": zz, "w2_num": [2.6, 0.0], "w2_den": [1.0, 15.0], "delay": 0.15,
           "ms": 2.0}
    out["velocity"] = robustness(sens, comp, w2, 2.0)
    out["rs_with_delay_inside"] = sup(lambda w: w2(w) * comp_d(w))[0]
    # W2 covers the delay: max |e^{-jwD} - 1| / |W2| < 1.
    out["delay_cover_ratio"] = float(np.max(np.abs(np.exp(-1j * GRID * 0.15) - 1.0) / np.abs(w2(GRID))))

    load_factor = tf([2.0 * zz, 1.0], [1.0, 2.0 * zz, 1.0])

    def phil(k):
        return lambda w: k * track(w) * load_factor(w) / (1j * w + k * track(w))

    def rs_fun(k, sign=1.0):
        return lambda w: w2(w) * (1j * w * comp(w) + sign * k * track(w)) / (1j * w + k * track(w))

    def nominal_peak(k):
        return sup(phil(k))[0]

    def rs_peak(k, sign=1.0):
        return sup(rs_fun(k, sign))[0]

    kpp_nominal = optimize.brentq(lambda k: nominal_peak(k) - 1.0, 0.1, 0.3, xtol=1e-10)
    kpp_rs = optimize.brentq(lambda k: rs_peak(k) - 1.0, 1.0, 5.0, xtol=1e-10)
    kpp_rs_printed = optimize.brentq(lambda k: rs_peak(k, -1.0) - 1.0, 1.0, 5.0, xtol=1e-10)

    def margin_ok(k):
        tv = track(GRID)
        w2tv = np.abs(w2(GRID) * tv)
        m = np.abs(1j * GRID + k * tv) - w2tv * np.abs(1j * GRID + k) - k * (np.abs(tv) + w2tv)
        return bool(np.min(m) >= 0.0)

    lo, hi = 1e-4, 1.0
    for _ in range(80):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if margin_ok(mid) else (lo, mid)
    kpp_rp = lo

    theta = np.linspace(0.0, 2.0 * math.pi, 512, endpoint=False)
    coarse = np.logspace(-3.0, 3.0, 6001)

    def worst(k):
        def at(w, th):
            w = min(max(w, 1e-3), 1e3)  # the grid range of the C++ search
            s = 1j * w
            tv = track(np.array([w]))[0]
            d = np.exp(1j * th)
            wt = w2(np.array([w]))[0]
            return abs(k * tv * (1.0 + d * wt) / (s + k * tv + d * wt * (s * tv + k * tv)))
        s = 1j * coarse[:, None]
        tv = track(coarse)[:, None]
        wt = w2(coarse)[:, None]
        d = np.exp(1j * theta)[None, :]
        v = np.abs(k * tv * (1.0 + d * wt) / (s + k * tv + d * wt * (s * tv + k * tv)))
        i, j = np.unravel_index(int(np.argmax(v)), v.shape)
        res = optimize.minimize(lambda x: -at(math.exp(x[0]), x[1]), [math.log(coarse[i]), theta[j]],
                                method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-15, "maxiter": 4000})
        return max(float(v[i, j]), -float(res.fun))

    kpp_rp_exact = optimize.brentq(lambda k: worst(k) - 1.0, 0.01, 1.0, xtol=1e-9)

    bw_grid = np.logspace(-4.0, 2.0, 600001)
    mag = np.abs(phil(kpp_nominal)(bw_grid))
    idx = int(np.argmax(mag < 10.0 ** (-3.0 / 20.0)))
    j1 = optimize.brentq(lambda w: abs(phil(kpp_nominal)(np.array([w]))[0]) - 10.0 ** (-3.0 / 20.0),
                         bw_grid[idx - 1], bw_grid[idx], xtol=1e-14)

    # phi_l/Tl for the frictionless plant (Il = k = r^2 - 1, b = 2 zz k, bm = bl = 0), Tl opposing.
    il = r * r - 1.0
    kk = il
    b = 2.0 * zz * kk
    # Open plant: omega_m/Tm = (Il s^2 + b s + k)/D', omega_m/Tl = -(b s + k)/D', omega_l/Tl = -(s^2 + b s + k)/D'
    # with D' = [(s^2 + b s + k)(Il s^2 + b s + k) - (b s + k)^2]/s.
    full = np.polysub(np.polymul([1.0, b, kk], [il, b, kk]), np.polymul([b, kk], [b, kk]))
    dprime = full[:-1]  # divide by s (the constant term is 0)
    assert abs(full[-1]) < 1e-12

    def phil_tl(k):
        def f(w):
            s = 1j * np.asarray(w)
            c = kp + ki / s
            pmm = np.polyval([il, b, kk], s) / np.polyval(dprime, s)
            pml = -np.polyval([b, kk], s) / np.polyval(dprime, s)
            plm = np.polyval([b, kk], s) / np.polyval(dprime, s)
            pll = -np.polyval([1.0, b, kk], s) / np.polyval(dprime, s)
            keq = c * (1.0 + k / s)  # 1-DoF: Tm = -C (1 + Kpp/s) omega_m
            wm = pml / (1.0 + pmm * keq)
            return (pll - plm * keq * wm) / s
        return f

    j2 = sup(phil_tl(kpp_nominal))[0]
    out["position"] = {
        "kpp_nominal": kpp_nominal, "kpp_rs": kpp_rs, "kpp_rs_printed_form": kpp_rs_printed, "kpp_rp": kpp_rp,
        "kpp_rp_exact": kpp_rp_exact, "j1": j1, "j2": j2,
        "peak_at_0_3": nominal_peak(0.3), "rs_at_2": rs_peak(2.0),
        "omega_min": 1e-3,
        "printed": {"kpp_rs": 2.0, "kpp_nominal": 0.3, "kpp_rp": 0.11},
    }
    return out


# ----------------------------------------------------------------------------- further robustness() cases
def cases():
    out = []
    # E26-b design with a torque-path delay inside the loop and a biproper weight.
    num, den = two_mass(3.0, 0.01)
    sens, comp, _ = velocity_loop(num, den, 6.117301, 1.491502, delay=0.15)
    w2n, w2d = [4.0, 4.0], [1.0, 20.0]
    out.append({"name": "E26-b with delay 0.15", "r": 3.0, "zeta_z": 0.01, "zeta_p": 0.03, "a": 0.0,
                "kp": 6.117301, "ki": 1.491502, "wp": 1.0, "delay": 0.15, "w2_num": w2n, "w2_den": w2d, "ms": 1.8,
                **robustness(sens, comp, tf(w2n, w2d), 1.8)})
    # E-fric plant (friction, a > 0), pole placement at w* = 0.6, z* = 0.8, 2-DoF wp = 0.5 (S, T unchanged).
    num, den = two_mass(3.0, 0.06, 0.15, 0.2)
    kp, ki = place(num, den, 0.6, 0.8)
    sens, comp, _ = velocity_loop(num, den, kp, ki, wp=0.5)
    w2n, w2d = [2.6, 0.0], [1.0, 15.0]
    out.append({"name": "E-fric placed at 0.6/0.8, wp 0.5", "r": 3.0, "zeta_z": 0.06, "zeta_p": 0.15, "a": 0.2,
                "kp": kp, "ki": ki, "wp": 0.5, "delay": 0.0, "w2_num": w2n, "w2_den": w2d, "ms": 2.0,
                **robustness(sens, comp, tf(w2n, w2d), 2.0)})
    return out


def largest_omega():
    """Largest w* (z* = 1, r = 3, zeta_z = 0.01) with W2 = 2.6 s/(s + 15) in normalized time."""
    num, den = two_mass(3.0, 0.01)
    rng = admissible_range(num, den, 1.0)
    w2 = tf([2.6, 0.0], [1.0, 15.0])
    ms = 2.0

    def values(w):
        kp, ki = place(num, den, w, 1.0)
        sens, comp, _ = velocity_loop(num, den, kp, ki)
        return robustness(sens, comp, w2, ms)

    top = values(rng["omega_max"])
    res = {"zeta_star": 1.0, "ms": ms, "omega_max": rng["omega_max"], "at_omega_max": top}
    res["rs_limit"] = optimize.brentq(lambda w: values(w)["rs"] - 1.0, 0.05, rng["omega_max"], xtol=1e-10) \
        if top["rs"] > 1.0 else rng["omega_max"]
    res["rp_limit"] = optimize.brentq(lambda w: values(w)["rp"] - 1.0, 0.05, rng["omega_max"], xtol=1e-10) \
        if top["rp"] > 1.0 else rng["omega_max"]
    res["np_at_rp_limit"] = values(res["rp_limit"])["np"]
    return res


def main():
    data = {"generator": "tools/reference/tuning_robust_reference.py", "e27": e27(), "robustness": cases(),
            "largest_omega_star": largest_omega()}
    with open(OUT, "w") as f:
        json.dump(data, f, indent=1)
    print(json.dumps(data, indent=1))


if __name__ == "__main__":
    main()
