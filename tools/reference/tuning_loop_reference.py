#!/usr/bin/env python3
"""Reference values for the velocity-loop indices (module `tuning`, loop_analysis.hpp; catalog
C7.8, C7.15; issue-7 plan sections 1.6 and 1.14).

Writes tests/data/tuning/loop_reference.json. Everything is computed here independently of the
C++ code:

  * The two-mass plant is written from its equations of motion (Im = 1, frictionless realization
    Il = k = r^2 - 1, b = 2 zeta_z (r^2 - 1), derived by matching (1/s)(s^2 + 2 zz s + 1)/(s^2 +
    2 zz r^2 s + r^2), which is asserted), the determinant divided by s with numpy.polydiv.
  * Frequency functions by complex arithmetic of the block diagram (numpy.polyval at j w, the delay
    as exp(-j w T) exactly), not from the rational closed loop.
  * Peaks: a 200 001-point log grid over [1e-3, 1e3] plus the frequencies of the lightly damped
    closed-loop poles, every local maximum refined by scipy.optimize.minimize_scalar (bounded,
    xatol 1e-12 in log w).
  * Bandwidth: the first sign change of |f| - 10^(-3/20) on that grid, scipy.optimize.brentq.
  * Margins: every sign change of |L| - 1 (gain crossings) and of Im L with Re L < 0 (phase
    crossings) on the grid, brentq; the margin of smallest magnitude is reported (MATLAB's
    `margin` convention). Phase margin = principal arg(L) + 180 deg wrapped to (-180, 180].
  * Time responses: the rational closed loop over Delta = dC dA dF dP + nC nA nF nP (the delay as
    the (6,6) Pade approximant from scipy.interpolate.pade of the Taylor series of exp(-sT)),
    simulated by scipy.signal.lsim on a uniform grid of 400 001 points over 60 time constants of
    the slowest closed-loop pole (a horizon 5x the C++ one, so the truncation is negligible).
    Overshoot = max y - 1, settling = last exit from the 2 % band (linear interpolation), ITAE by
    scipy.integrate.simpson of t |wl(t)|, peak |u| = max |u|.
  * J2 = sup|wl/Tl_cl W| / sup|wl/Tl_ol W| with W = s/(s+1), both peaks as above.

Loops (sources): E26 (catalog E26 / plan section 2: r = 3, zeta_z = 0.01, zeta* = 1, w* = 0.30,
gains 4.634937, 0.640260 recomputed here by placing c(s) = 0 at the double pole), E26-b
(zeta* = 0.8, w* = 0.5), E-PID on a damped plant (r = 4, zeta_z = 0.01, Kd = 4, tau = 0.01,
zeta* = sqrt(1/2), w* = 0.5; gains placed here), E26 gains with a feedback filter tau_f = 0.01 and
a delay 0.15 (catalog E26/E27 robustness part), E26-b with w_p = 0.5, and the E24 plant (r = 3,
zeta_z = 0.0125, tau_f = 0.01) with the rigid PI gains of E24 (min closed-loop damping, plan
section 2 row E24-qual).

Run:  /usr/bin/python3 tools/reference/tuning_loop_reference.py   (numpy, scipy)
"""
import json
import math
import os

import numpy as np
from scipy import integrate, interpolate, optimize, signal

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "tuning", "loop_reference.json")
LEVEL = 10.0 ** (-3.0 / 20.0)
PADE_ORDER = 6


# ----------------------------------------------------------------------------- plant
def two_mass(r, zeta_z):
    """Frictionless normalized two-mass plant polynomials from the equations of motion (Im = 1)."""
    il = r * r - 1.0
    k = il
    b = 2.0 * zeta_z * il
    c = np.array([b, k])                       # shaft coupling b s + k
    m = np.polyadd([1.0, 0.0, 0.0], c)         # s^2 + bm s + c, bm = 0
    lr = np.polyadd([il, 0.0, 0.0], c)         # Il s^2 + bl s + c, bl = 0
    det = np.polysub(np.polymul(m, lr), np.polymul(c, c))
    dprime, rem = np.polydiv(det, [1.0, 0.0])
    assert np.max(np.abs(rem)) < 1e-12
    plant = {"den": dprime, "wm_tm": lr, "wl_tm": c, "wm_tl": -c, "wl_tl": -m}
    # Check against the normalized design model (catalog section 0).
    want_num = np.array([1.0, 2.0 * zeta_z, 1.0])
    want_den = np.polymul([1.0, 0.0], [1.0, 2.0 * zeta_z * r * r, r * r])
    for w in (0.1, 0.7, 2.9, 11.0):
        s = 1j * w
        got = np.polyval(lr, s) / np.polyval(dprime, s)
        want = np.polyval(want_num, s) / np.polyval(want_den, s)
        assert abs(got - want) < 1e-12 * abs(want)
    return plant


def pade(delay, order):
    if delay == 0.0:
        return np.array([1.0]), np.array([1.0])
    # Pade of exp(-x) in x = s T (well conditioned), then x -> s T.
    taylor = [(-1.0) ** k / math.factorial(k) for k in range(2 * order + 1)]
    p, q = interpolate.pade(taylor, order)
    scale = delay ** np.arange(order, -1, -1)
    pc, qc = np.array(p.coeffs) * scale, np.array(q.coeffs) * scale
    return pc / qc[0], qc / qc[0]


# ----------------------------------------------------------------------------- loop
class Loop:
    def __init__(self, plant, kp, ki, kd=0.0, tau=0.0, wp=1.0, wd=0.0, tau_f=0.0, delay=0.0):
        self.p = plant
        self.kp, self.ki, self.kd, self.tau, self.wp, self.wd = kp, ki, kd, tau, wp, wd
        self.tau_f, self.delay = tau_f, delay
        # Rational parts.
        self.nC = np.polyadd(np.polymul([kp, ki], [tau, 1.0]), [kd, 0.0, 0.0])
        self.nR = np.polyadd(np.polymul([wp * kp, ki], [tau, 1.0]), [wd * kd, 0.0, 0.0])
        self.dC = np.polymul([1.0, 0.0], [tau, 1.0]) if tau > 0 else np.array([1.0, 0.0])
        self.nF, self.dF = np.array([1.0]), np.array([tau_f, 1.0]) if tau_f > 0 else np.array([1.0])
        self.nA, self.dA = pade(delay, PADE_ORDER)
        dp = plant["den"]
        self.delta = np.polyadd(
            np.polymul(np.polymul(self.dC, self.dA), np.polymul(self.dF, dp)),
            np.polymul(np.polymul(self.nC, self.nA), np.polymul(self.nF, plant["wm_tm"])))
        self.poles = np.roots(self.delta)

    # Frequency functions from the block diagram, delay exact.
    def _c(self, w):
        s = 1j * w
        return np.polyval(self.nC, s) / np.polyval(self.dC, s)

    def _r(self, w):
        s = 1j * w
        return np.polyval(self.nR, s) / np.polyval(self.dC, s)

    def _a(self, w):
        return np.exp(-1j * w * self.delay)

    def _f(self, w):
        return 1.0 / (1.0 + 1j * w * self.tau_f)

    def _pl(self, key, w):
        s = 1j * w
        return np.polyval(self.p[key], s) / np.polyval(self.p["den"], s)

    def loop_gain(self, w):
        return self._c(w) * self._f(w) * self._a(w) * self._pl("wm_tm", w)

    def sens(self, w):
        return 1.0 / (1.0 + self.loop_gain(w))

    def comp(self, w):
        l = self.loop_gain(w)
        return l / (1.0 + l)

    def motor_tracking(self, w):
        return self._r(w) * self._a(w) * self._pl("wm_tm", w) * self.sens(w)

    def load_tracking(self, w):
        return self._r(w) * self._a(w) * self._pl("wl_tm", w) * self.sens(w)

    def load_dist(self, w):
        # wl = Pl_Tl Tl + A Pl u, u = -C F wm, wm = Pm_Tl Tl / (1 + L)
        return self._pl("wl_tl", w) - self._a(w) * self._pl("wl_tm", w) * self._c(w) * self._f(w) * \
            self._pl("wm_tl", w) * self.sens(w)

    def load_dist_open(self, w):
        return self._pl("wl_tl", w)

    # Rational closed loop over Delta (derivation in loop_analysis tests' header comment):
    #   wm/w* = nA nPm nR dF / Delta, wl/w* = nA nPl nR dF / Delta, u/w* = nR dA dF dP / Delta,
    #   wl/Tl = (nLL dC dA dF - s nC nA nF) / Delta   (nLL nPm - nPl nML = -s dP for the two-mass).
    def rational(self, which):
        mul = lambda *ps: ps[0] if len(ps) == 1 else np.polymul(ps[0], mul(*ps[1:]))
        if which == "motor":
            num = mul(self.nA, self.p["wm_tm"], self.nR, self.dF)
        elif which == "load":
            num = mul(self.nA, self.p["wl_tm"], self.nR, self.dF)
        elif which == "effort":
            num = mul(self.nR, self.dA, self.dF, self.p["den"])
        elif which == "load_dist":
            num = np.polysub(mul(self.p["wl_tl"], self.dC, self.dA, self.dF),
                             mul([1.0, 0.0], self.nC, self.nA, self.nF))
        return num, self.delta


def check_rational(loop):
    """The rational closed loop agrees with the block diagram (delay-free loops only)."""
    if loop.delay > 0:
        return
    for which, f in (("motor", loop.motor_tracking), ("load", loop.load_tracking),
                     ("load_dist", loop.load_dist)):
        num, den = loop.rational(which)
        for w in (0.05, 0.9, 3.3, 40.0):
            got = np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
            assert abs(got - f(w)) < 1e-9 * max(abs(f(w)), 1e-3), (which, w, got, f(w))


# ----------------------------------------------------------------------------- indices
def grid_for(loop, extra=()):
    g = np.logspace(-3, 3, 200001)
    pts = [abs(p.imag) for p in loop.poles if abs(p) > 0 and -p.real / abs(p) < 0.5 and 1e-3 < abs(p.imag) < 1e3]
    return np.unique(np.concatenate([g, pts, list(extra)]))


def peak(f, grid):
    mags = np.abs(f(grid))
    best_val, best_w = float(mags.max()), float(grid[mags.argmax()])
    idx = [i for i in range(len(grid)) if (i == 0 or mags[i] > mags[i - 1]) and (i == len(grid) - 1 or mags[i] >= mags[i + 1])]
    idx = sorted(idx, key=lambda i: -mags[i])[:20]
    for i in idx:
        lo, hi = math.log(grid[max(i - 1, 0)]), math.log(grid[min(i + 1, len(grid) - 1)])
        if hi <= lo:
            continue
        res = optimize.minimize_scalar(lambda x: -abs(f(math.exp(x))), bounds=(lo, hi), method="bounded",
                                       options={"xatol": 1e-12})
        if -res.fun > best_val:
            best_val, best_w = float(-res.fun), float(math.exp(res.x))
    return best_val, best_w


def bandwidth(f, grid):
    mags = np.abs(f(grid)) - LEVEL
    i = int(np.argmax(mags < 0))
    assert mags[i] < 0 and i > 0
    return optimize.brentq(lambda w: abs(f(w)) - LEVEL, grid[i - 1], grid[i], xtol=1e-14, rtol=1e-14)


def margins(loop, grid):
    l = loop.loop_gain(grid)
    gm = math.inf
    pm = math.inf
    im = l.imag
    for i in np.nonzero(np.sign(im[:-1]) != np.sign(im[1:]))[0]:
        w = optimize.brentq(lambda x: loop.loop_gain(x).imag, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15)
        v = loop.loop_gain(w)
        if v.real < 0:
            m = -20.0 * math.log10(abs(v))
            if abs(m) < abs(gm):
                gm = m
    g = np.abs(l) - 1.0
    for i in np.nonzero(np.sign(g[:-1]) != np.sign(g[1:]))[0]:
        w = optimize.brentq(lambda x: abs(loop.loop_gain(x)) - 1.0, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15)
        ph = math.degrees(np.angle(loop.loop_gain(w))) + 180.0
        if ph > 180.0:
            ph -= 360.0
        if abs(ph) < abs(pm):
            pm = ph
    return gm, pm


def time_indices(loop):
    sigma = min(-p.real for p in loop.poles)
    assert sigma > 0
    horizon = 60.0 / sigma
    t = np.linspace(0.0, horizon, 400001)
    one = np.ones_like(t)

    def resp(which):
        num, den = loop.rational(which)
        _, y, _ = signal.lsim((num, den), one, t)
        return y

    y_load = resp("load")
    over = max(float(np.max(y_load)) - 1.0, 0.0)
    outside = np.nonzero(np.abs(y_load - 1.0) > 0.02)[0]
    k = int(outside[-1])
    e0, e1 = abs(y_load[k] - 1.0) - 0.02, abs(y_load[k + 1] - 1.0) - 0.02
    settle = float(t[k] + (t[k + 1] - t[k]) * e0 / (e0 - e1))
    y_motor = resp("motor")
    over_m = max(float(np.max(y_motor)) - 1.0, 0.0)
    outside = np.nonzero(np.abs(y_motor - 1.0) > 0.02)[0]
    k = int(outside[-1])
    e0, e1 = abs(y_motor[k] - 1.0) - 0.02, abs(y_motor[k + 1] - 1.0) - 0.02
    settle_m = float(t[k] + (t[k + 1] - t[k]) * e0 / (e0 - e1))
    u = resp("effort")
    yd = resp("load_dist")
    itae = float(integrate.simpson(t * np.abs(yd), x=t))
    return {"overshoot": over, "settling_time": settle, "overshoot_motor": over_m, "settling_time_motor": settle_m,
            "peak_torque_step": float(np.max(np.abs(u))), "itae_load_step": itae,
            "horizon": horizon}


def analyse(loop, r):
    check_rational(loop)
    grid = grid_for(loop, extra=(1.0, r))
    w_ = lambda s: s / (s + 1.0)
    out = {}
    out["stable"] = bool(np.all(loop.poles.real < 0))
    out["poles"] = sorted([[float(p.real), float(p.imag)] for p in loop.poles], key=lambda x: (math.hypot(*x), x[0], -x[1]))
    out["min_damping"] = float(min(-p.real / abs(p) for p in loop.poles))
    out["peak_s"], out["peak_s_omega"] = peak(loop.sens, grid)
    out["peak_t"], _ = peak(loop.comp, grid)
    out["peak_tm"], _ = peak(loop.motor_tracking, grid)
    out["peak_tl"], _ = peak(loop.load_tracking, grid)
    out["peak_load_disturbance"], _ = peak(loop.load_dist, grid)
    cl, _ = peak(lambda w: loop.load_dist(w) * w_(1j * w), grid)
    ol, _ = peak(lambda w: loop.load_dist_open(w) * w_(1j * w), grid)
    out["j2"] = cl / ol
    out["j2_open_peak"] = ol
    out["bandwidth_motor"] = bandwidth(loop.motor_tracking, grid)
    out["bandwidth_load"] = bandwidth(loop.load_tracking, grid)
    out["gain_margin_db"], out["phase_margin_deg"] = margins(loop, grid)
    out["modulus_margin"] = 1.0 / out["peak_s"]
    out["hf_controller_gain"] = float(abs(loop._c(10.0 * r)))
    out.update(time_indices(loop))
    return out


# ----------------------------------------------------------------------------- designs
def place(plant_num, plant_den, w, z, kd=0.0, tau=0.0):
    """(Kp, Ki) with c(s) = s (tau s + 1) Dp + [(Kp s + Ki)(tau s + 1) + Kd s^2] N zero at the pair:
    for z < 1 the complex pole's Re/Im parts, for z = 1 c(-w) = c'(-w) = 0 (catalog C7.3)."""
    base = np.polyadd(np.polymul(np.polymul([1.0, 0.0], [tau, 1.0]), plant_den), np.polymul([kd, 0.0, 0.0], plant_num))
    cp = np.polymul(np.polymul([1.0, 0.0], [tau, 1.0]), plant_num)  # coefficient of Kp
    ci = np.polymul([tau, 1.0], plant_num)                          # coefficient of Ki
    if z < 1.0:
        s1 = w * (-z + 1j * math.sqrt(1.0 - z * z))
        m = np.array([[np.polyval(cp, s1).real, np.polyval(ci, s1).real],
                      [np.polyval(cp, s1).imag, np.polyval(ci, s1).imag]])
        rhs = -np.array([np.polyval(base, s1).real, np.polyval(base, s1).imag])
    else:
        s1 = -w
        m = np.array([[np.polyval(cp, s1), np.polyval(ci, s1)],
                      [np.polyval(np.polyder(cp), s1), np.polyval(np.polyder(ci), s1)]])
        rhs = -np.array([np.polyval(base, s1), np.polyval(np.polyder(base), s1)])
    kp, ki = np.linalg.solve(m, rhs)
    return float(kp), float(ki)


def design_model(r, zz):
    return np.array([1.0, 2.0 * zz, 1.0]), np.polymul([1.0, 0.0], [1.0, 2.0 * zz * r * r, r * r])


def finite_or_null(x):
    """JSON has no infinity: +inf (no crossing) is written as null."""
    if isinstance(x, dict):
        return {k: finite_or_null(v) for k, v in x.items()}
    if isinstance(x, list):
        return [finite_or_null(v) for v in x]
    if isinstance(x, float) and math.isinf(x):
        assert x > 0
        return None
    return x


def j1_over_wp(plant, kp, ki, limit, grid):
    """max over wp in [0, 1] of the load bandwidth with sup|wl/w*| <= limit: a 201-point wp grid,
    then brentq on every feasible/infeasible boundary of the grid and a bounded refinement of
    interior maxima."""
    def peak_bw(wp):
        loop = Loop(plant, kp, ki, wp=wp)
        return peak(loop.load_tracking, grid)[0], bandwidth(loop.load_tracking, grid)

    wps = np.linspace(0.0, 1.0, 201)
    vals = [peak_bw(w) for w in wps]
    score = [bw if pk <= limit else -1.0 for pk, bw in vals]
    best = int(np.argmax(score))
    best_wp, best_j1 = float(wps[best]), float(score[best])
    for i in range(len(wps) - 1):
        if (score[i] < 0) != (score[i + 1] < 0):
            b = optimize.brentq(lambda w: peak_bw(w)[0] - limit, wps[i], wps[i + 1], xtol=1e-13)
            inside = b - 1e-10 if score[i] >= 0 else b + 1e-10
            pk, bw = peak_bw(inside)
            if pk <= limit and bw > best_j1:
                best_wp, best_j1 = inside, bw
    if 0 < best < len(wps) - 1 and score[best - 1] >= 0 and score[best + 1] >= 0:
        res = optimize.minimize_scalar(lambda w: -peak_bw(w)[1], bounds=(wps[best - 1], wps[best + 1]),
                                       method="bounded", options={"xatol": 1e-10})
        if peak_bw(res.x)[0] <= limit and -res.fun > best_j1:
            best_wp, best_j1 = float(res.x), float(-res.fun)
    return best_j1, best_wp


def j_scan():
    """J1 (peak limit 1.3) and J2 over w* on the E26 plant, zeta* = 1 (catalog C7.8 indices)."""
    plant = two_mass(3.0, 0.01)
    grid = np.unique(np.concatenate([np.logspace(-3, 3, 20001), [1.0, 3.0]]))
    w_ = lambda s: s / (s + 1.0)
    rows = []
    for w in (0.1, 0.2, 0.3, 0.45, 0.6):
        kp, ki = place(*design_model(3.0, 0.01), w, 1.0)
        loop = Loop(plant, kp, ki)
        extra = grid_for(loop, extra=(1.0, 3.0))
        cl, _ = peak(lambda x: loop.load_dist(x) * w_(1j * x), extra)
        ol, _ = peak(lambda x: loop.load_dist_open(x) * w_(1j * x), extra)
        j1, wp = j1_over_wp(plant, kp, ki, 1.3, grid)
        rows.append({"omega_star": w, "kp": kp, "ki": ki, "j2": cl / ol, "j1": j1, "wp": wp})
        print("scan", rows[-1])
    return {"r": 3.0, "zeta_z": 0.01, "zeta_star": 1.0, "peak_limit": 1.3, "rows": rows}


def main():
    cases = []

    def add(name, r, zz, kp, ki, source, **kw):
        loop = Loop(two_mass(r, zz), kp, ki, **kw)
        res = analyse(loop, r)
        entry = {"name": name, "source": source, "r": r, "zeta_z": zz, "kp": kp, "ki": ki,
                 "kd": kw.get("kd", 0.0), "tau": kw.get("tau", 0.0), "wp": kw.get("wp", 1.0),
                 "tau_f": kw.get("tau_f", 0.0), "delay": kw.get("delay", 0.0)}
        entry.update(res)
        cases.append(entry)
        print(name, {k: (round(v, 6) if isinstance(v, float) else v) for k, v in res.items() if k != "poles"})

    kp, ki = place(*design_model(3.0, 0.01), 0.30, 1.0)
    assert abs(kp - 4.634937) < 1e-6 and abs(ki - 0.640260) < 1e-6  # catalog E26
    add("E26", 3.0, 0.01, kp, ki, "catalog E26 (r=3, zz=0.01, z*=1, w*=0.30)")
    add("E26_hf", 3.0, 0.01, kp, ki, "E26 gains with tau_f=0.01 feedback filter and delay 0.15 (E26/E27)",
        tau_f=0.01, delay=0.15)
    kpb, kib = place(*design_model(3.0, 0.01), 0.5, 0.8)
    assert abs(kpb - 6.117301) < 1e-6 and abs(kib - 1.491502) < 1e-6  # catalog E26 extra
    add("E26b", 3.0, 0.01, kpb, kib, "catalog E26 extra (z*=0.8, w*=0.5)")
    add("E26b_wp05", 3.0, 0.01, kpb, kib, "E26-b with setpoint weight wp=0.5", wp=0.5)
    kpd, kid = place(*design_model(4.0, 0.01), 0.5, math.sqrt(0.5), kd=4.0, tau=0.01)
    add("EPID", 4.0, 0.01, kpd, kid, "plan E-PID (r=4, rbar=2 -> Kd=4) on zz=0.01 with tau=0.01, placed here",
        kd=4.0, tau=0.01)
    # E24 plant (Im=1, Il=8, b=0.2, k=8 -> r=3, zz=0.0125) with the rigid gains and the feedback LPF.
    for w, g in ((0.3, (4.32, 0.81)), (0.6, (8.64, 3.24)), (2.0, (28.8, 36.0)), ("SO", (450.0, 11250.0))):
        loop = Loop(two_mass(3.0, 0.0125), g[0], g[1], tau_f=0.01)
        zmin = min(-p.real / abs(p) for p in loop.poles)
        print("E24-qual", w, g, "min damping %.4f" % zmin)

    # Unstable: the E24 w*=2 rigid gains on the E26 plant with the delay 0.15.
    bad = Loop(two_mass(3.0, 0.01), 28.8, 36.0, delay=0.15)
    unstable = {"r": 3.0, "zeta_z": 0.01, "kp": 28.8, "ki": 36.0, "delay": 0.15,
                "max_real": float(max(bad.poles.real))}
    assert unstable["max_real"] > 0
    print("unstable case max Re", unstable["max_real"])

    out = {"generator": "tools/reference/tuning_loop_reference.py", "pade_order": PADE_ORDER,
           "level": LEVEL, "cases": cases, "unstable": unstable,
           "scan": j_scan()}
    with open(OUT, "w") as fh:
        json.dump(finite_or_null(out), fh, indent=1)
    print("wrote", OUT)


if __name__ == "__main__":
    main()
