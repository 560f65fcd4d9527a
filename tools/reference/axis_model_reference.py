#!/usr/bin/env python3
"""Reference values for the rapid axis model's tests (tests/rapid/test_axis_model*.cpp).

Writes tests/data/rapid/axis_model_reference.json. Computed independently of the C++ code:

* poles and zeros: numpy.roots of the Eq. 3.3 polynomials;
* frequency responses: scipy.signal.freqs of tracking (b0 s^3 + b1 s^2 + b2 s + a3)/(s^3 + a1 s^2
  + a2 s + a3) and disturbance -s/(s^3 + a1 s^2 + a2 s + a3), always in the uncancelled form;
* bandwidth: a 20000-point log scan of |G| and scipy.optimize.brentq on |G| - 10^(-3/20) |G(0)|;
* simulations without friction switching: scipy.signal.lsim (interp=False: inputs held between
  samples at their midpoint values, the mean of samples k and k+1) of the state-space model x'' = -a1 x' - a2 x + a3 e_i + b0 x_r'' + b1 x_r' + b2 x_r - d,
  e_i' = x_r - x with the three command signals as separate inputs (d0 = d1 = d constant);
* simulations with Coulomb friction: scipy.integrate.solve_ivp (DOP853, rtol 1e-13) per sample,
  with terminal events at velocity zero crossings and the stick/breakaway rule of the header
  (Karnopp: stuck while d1 <= g <= d0, g = -a2 x + a3 e_i + w; breakaway at the analytic instant
  when the linearly growing g leaves the band; inverted band d0 < d1: direction + iff
  g >= (d0 + d1)/2).

Commands: trapezoidal-velocity moves sampled at 1 kHz, generated here in closed form and stored in
the fixture. Command derivatives: the command is padded with its end values, then
x_r'_k = (x_r,k+1 - x_r,k-1)/(2 ts) and x_r''_k = (x_r'_k+1 - x_r'_k-1)/(2 ts); over the sample from
k to k+1 the inputs are held at the mean of their values at k and k+1 (midpoint hold).

Run:  /usr/bin/python3 tools/reference/axis_model_reference.py
"""

import json
import math
import os

import numpy as np
import scipy.integrate as si
import scipy.optimize as so
import scipy.signal as ss

TS = 1e-3
OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "rapid", "axis_model_reference.json")

# Thesis Tables 3.3-3.5 (X axes) and a few special cases.
MODELS = {
    "ppi_x_actual": dict(a1=372.76, a2=62009.83, a3=1527104.87, b0=0.0, b1=0.0, b2=11106.33, d0=441.0, d1=-302.0),
    "ppi_x_estimated": dict(a1=2648.46, a2=776813.58, a3=21349028.29, b0=1.08, b1=-415.03, b2=65194.67, d0=7210.0,
                            d1=-5277.0),
    "pid_x_actual": dict(a1=192.65, a2=44356.23, a3=316830.21, b0=0.0, b1=190.10, b2=44356.23, d0=441.0, d1=-302.0),
    "pid_x_estimated": dict(a1=214.13, a2=60040.19, a3=685295.65, b0=-0.35, b1=203.86, b2=60043.78, d0=620.0,
                            d1=-280.0),
    "smc_x_actual": dict(a1=390.10, a2=57029.44, a3=3801962.50, b0=1.0, b1=390.10, b2=57029.44, d0=441.0, d1=-302.0),
    "smc_x_estimated": dict(a1=566.95, a2=370137.94, a3=15346572.85, b0=0.85, b1=574.83, b2=370142.25, d0=2367.0,
                            d1=-1858.0),
    # a3 = 0: P position loop with velocity feedforward, no integrator.
    "no_integrator": dict(a1=150.0, a2=30000.0, a3=0.0, b0=0.0, b1=100.0, b2=30000.0, d0=200.0, d1=-150.0),
}


def unstable_model():
    """Poles 2 +- 200j and -30: a growing oscillation."""
    a = np.real(np.poly([2 + 200j, 2 - 200j, -30.0]))
    return dict(a1=a[1], a2=a[2], a3=a[3], b0=0.0, b1=50.0, b2=a[2], d0=0.0, d1=0.0)


MODELS["unstable"] = unstable_model()


def tracking_tf(m):
    return [m["b0"], m["b1"], m["b2"], m["a3"]], [1.0, m["a1"], m["a2"], m["a3"]]


def disturbance_tf(m):
    return [-1.0, 0.0], [1.0, m["a1"], m["a2"], m["a3"]]


def modal(roots):
    out = []
    for r in sorted(roots, key=lambda z: (abs(z), z.real, -z.imag)):
        w = abs(r)
        out.append(dict(re=r.real, im=r.imag, freq_hz=w / (2 * math.pi), zeta=(-r.real / w) if w > 0 else 1.0))
    return out


def trim_leading_zeros(c):
    c = list(c)
    while c and c[0] == 0.0:
        c.pop(0)
    return c


def reduced(num, den, m):
    """Cancel the exact common factor s when a3 = 0 (only for roots; freqs uses the full form)."""
    if m["a3"] == 0.0:
        return num[:-1], den[:-1]
    return num, den


def bandwidth_hz(m):
    num, den = tracking_tf(m)
    rnum, rden = reduced(num, den, m)
    dc = abs(rnum[-1] / rden[-1])
    thr = dc * 10 ** (-3 / 20)
    f = np.logspace(-4, math.log10(0.5 / TS), 20000)
    _, h = ss.freqs(num, den, worN=2 * math.pi * f)
    g = np.abs(h)
    idx = np.nonzero(g < thr)[0]
    if len(idx) == 0:
        return math.inf
    i = idx[0]

    def fn(fr):
        return abs(ss.freqs(num, den, worN=[2 * math.pi * fr])[1][0]) - thr

    return so.brentq(fn, f[i - 1], f[i], xtol=1e-14, rtol=1e-15)


# ---------------------------------------------------------------------------------------------
# Commands
# ---------------------------------------------------------------------------------------------
def move_profile(distance, vmax, amax):
    """Trapezoidal (or triangular) velocity profile: returns (duration, position(t) function)."""
    d = abs(distance)
    sgn = 1.0 if distance >= 0 else -1.0
    if d == 0.0:
        return 0.0, lambda t: 0.0
    ta = vmax / amax
    if amax * ta * ta >= d:  # triangular
        ta = math.sqrt(d / amax)
        vp = amax * ta
        tc = 0.0
    else:
        vp = vmax
        tc = (d - amax * ta * ta) / vmax
    total = 2 * ta + tc

    def pos(t):
        if t <= 0:
            return 0.0
        if t < ta:
            return sgn * 0.5 * amax * t * t
        if t < ta + tc:
            return sgn * (0.5 * amax * ta * ta + vp * (t - ta))
        if t < total:
            r = total - t
            return sgn * (d - 0.5 * amax * r * r)
        return sgn * d

    return total, pos


def trajectory(start, targets, vmax, amax, dwell, ts=TS, tail=0.2):
    """Samples of moves start -> targets[0] -> ... with `dwell` s at rest before each move."""
    segments = []
    t0 = dwell
    pos = start
    for target in targets:
        dur, f = move_profile(target - pos, vmax, amax)
        segments.append((t0, dur, pos, f))
        t0 += dur + dwell
        pos = target
    total = t0 + tail
    n = int(round(total / ts)) + 1
    x = np.full(n, float(start))
    for k in range(n):
        t = k * ts
        value = start
        for (s0, dur, p0, f) in segments:
            if t >= s0:
                value = p0 + f(t - s0)
        x[k] = value
    return x


def held_inputs(cmd):
    """x_r, x_r', x_r'' held over each sample (midpoint hold of the padded central differences)."""
    p = np.concatenate(([cmd[0]] * 2, cmd, [cmd[-1]] * 3))
    v = (p[2:] - p[:-2]) / (2 * TS)  # v[j]: derivative at padded index j+1, i.e. cmd index j-1
    a = (v[2:] - v[:-2]) / (2 * TS)  # a[j]: cmd index j
    n = len(cmd)
    xd = v[1:n + 2]  # cmd indices 0 .. n
    xdd = a[:n + 1]
    xr = np.asarray(cmd, dtype=float)
    xr_next = np.concatenate((xr[1:], xr[-1:]))
    return 0.5 * (xr + xr_next), 0.5 * (xd[:n] + xd[1:n + 1]), 0.5 * (xdd[:n] + xdd[1:n + 1])


def rest_position(m, xr0):
    """Where the model rests under the constant command xr0 (the simulation's default start)."""
    if m["a3"] == 0 and m["a2"] != 0:
        return m["b2"] / m["a2"] * xr0
    return xr0


def equilibrium_integrator(m, x0, xr0):
    """e_i with zero net drive at rest: a3 e_i = a2 x0 - b2 xr0."""
    return (m["a2"] * x0 - m["b2"] * xr0) / m["a3"] if m["a3"] != 0 else 0.0


# ---------------------------------------------------------------------------------------------
# Linear simulation: lsim with held inputs
# ---------------------------------------------------------------------------------------------
def lsim_case(name, model, cmd, d=0.0, x0=None, ei0=None):
    m = dict(model)
    xr = np.asarray(cmd)
    xr_h, xd, xdd = held_inputs(xr)
    x0 = rest_position(m, xr[0]) if x0 is None else x0
    ei0 = equilibrium_integrator(m, x0, xr[0]) if ei0 is None else ei0
    A = np.array([[0.0, 1.0, 0.0], [-m["a2"], -m["a1"], m["a3"]], [-1.0, 0.0, 0.0]])
    B = np.array([[0.0, 0.0, 0.0, 0.0], [m["b2"], m["b1"], m["b0"], -1.0], [1.0, 0.0, 0.0, 0.0]])
    C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    D = np.zeros((2, 4))
    U = np.column_stack([xr_h, xd, xdd, np.full(len(xr), d)])
    T = np.arange(len(xr)) * TS
    _, y, _ = ss.lsim((A, B, C, D), U, T, X0=[x0, 0.0, ei0], interp=False)
    m["d0"] = d
    m["d1"] = d
    return dict(name=name, model=m, x0=x0, ei0=ei0, command=xr.tolist(), position=y[:, 0].tolist(),
                velocity=y[:, 1].tolist())


# ---------------------------------------------------------------------------------------------
# Friction simulation: solve_ivp with events, Karnopp stick rule
# ---------------------------------------------------------------------------------------------
def friction_case(name, model, cmd, x0=None, ei0=None):
    m = model
    a1, a2, a3, b0, b1, b2, d0, d1 = (m[k] for k in ("a1", "a2", "a3", "b0", "b1", "b2", "d0", "d1"))
    xr_all = np.asarray(cmd, dtype=float)
    xr_held, xd_all, xdd_all = held_inputs(xr_all)
    x = rest_position(m, xr_all[0]) if x0 is None else x0
    ei = equilibrium_integrator(m, x, xr_all[0]) if ei0 is None else ei0
    v = 0.0
    mode = 0  # -1, 0 (stuck), +1
    last_dir = 0
    reversals = 0
    positions, velocities = [], []

    def decide(g):
        up, down = g > d0, g < d1
        if up and down:
            return 1 if g >= 0.5 * (d0 + d1) else -1
        return 1 if up else (-1 if down else 0)

    for k in range(len(xr_all)):
        positions.append(x)
        velocities.append(v)
        xr = xr_held[k]
        w = b2 * xr + b1 * xd_all[k] + b0 * xdd_all[k]
        t, t_end = 0.0, TS
        at_rest = v == 0.0
        while t_end - t > 1e-15:
            if at_rest:
                at_rest = False
                new = decide(-a2 * x + a3 * ei + w)
                if new != 0:
                    if last_dir != 0 and new != last_dir:
                        reversals += 1
                    last_dir = new
                mode = new
            if mode == 0:
                g = -a2 * x + a3 * ei + w
                rate = a3 * (xr - x)
                tb = math.inf
                if rate > 0:
                    tb = (d0 - g) / rate
                elif rate < 0:
                    tb = (d1 - g) / rate
                if not tb < t_end - t:
                    ei += (xr - x) * (t_end - t)
                    break
                ei += (xr - x) * tb
                t += tb
                mode = 1 if rate > 0 else -1
                if last_dir != 0 and mode != last_dir:
                    reversals += 1
                last_dir = mode
                continue
            f = d0 if mode > 0 else d1

            def rhs(_, z, f=f):
                return [z[1], -a2 * z[0] - a1 * z[1] + a3 * z[2] + w - f, xr - z[0]]

            def crossing(_, z):
                return z[1]

            crossing.terminal = True
            crossing.direction = -mode  # + motion ends when v decreases through 0
            scale = max(1.0, abs(x), abs(ei))
            sol = si.solve_ivp(rhs, (t, t_end), [x, v, ei], method="DOP853", rtol=1e-13,
                               atol=[1e-14 * scale, 1e-12 * scale, 1e-15 * scale], events=crossing)
            if sol.status == 1 and len(sol.t_events[0]) > 0:
                if not sol.t_events[0][0] > t:
                    raise RuntimeError(f"{name}: event at the start of a motion segment (sample {k})")
                te = sol.t_events[0][0]
                x, _, ei = sol.y_events[0][0]
                v = 0.0
                t = te
                at_rest = True
            else:
                x, v, ei = sol.y[:, -1]
                break
    return dict(name=name, model=dict(m), x0=positions[0], ei0=equilibrium_integrator(m, positions[0], xr_all[0])
                if ei0 is None else ei0, command=xr_all.tolist(), position=positions, velocity=velocities,
                reversals=reversals)


def json_number(v):
    """JSON has no infinity: written as the string "inf"."""
    return "inf" if math.isinf(v) else v


def main():
    out = {"ts": TS, "models": {}, "frf": [], "linear": [], "friction": []}
    f_hz = np.logspace(-1, math.log10(500.0), 40)
    for name, m in MODELS.items():
        num, den = tracking_tf(m)
        rnum, rden = reduced(num, den, m)
        out["models"][name] = dict(coefficients=m, poles=modal(np.roots(rden)),
                                   zeros=modal(np.roots(trim_leading_zeros(rnum))),
                                   bandwidth_hz=json_number(bandwidth_hz(m)) if name != "unstable" else None)
        w = 2 * math.pi * f_hz
        _, ht = ss.freqs(num, den, worN=w)
        dnum, dden = disturbance_tf(m)
        _, hd = ss.freqs(dnum, dden, worN=w)
        out["frf"].append(dict(model=name, omega=w.tolist(), tracking_re=ht.real.tolist(), tracking_im=ht.imag.tolist(),
                               disturbance_re=hd.real.tolist(), disturbance_im=hd.imag.tolist()))

    # Random-ish back-and-forth moves at several feeds (thesis-like identification command).
    moves = trajectory(0.0, [12.0, 4.0, 4.5, 20.0, 0.0, 7.0], vmax=150.0, amax=2000.0, dwell=0.05)
    offset = trajectory(100.0, [110.0, 96.0, 103.0], vmax=80.0, amax=1500.0, dwell=0.05)
    out["linear"].append(lsim_case("pid_moves", MODELS["pid_x_actual"], moves))
    out["linear"].append(lsim_case("ppi_offset", MODELS["ppi_x_actual"], offset))
    out["linear"].append(lsim_case("smc_constant_friction", MODELS["smc_x_actual"], moves, d=300.0))
    out["linear"].append(lsim_case("no_integrator", MODELS["no_integrator"], offset, d=-40.0))
    out["linear"].append(lsim_case("unstable", MODELS["unstable"], moves[:1500]))
    # Degenerate: no a coefficients at all (x'' = b0 x_r'' + b1 x_r' + b2 x_r - d, triple pole at 0).
    b_only = dict(a1=0.0, a2=0.0, a3=0.0, b0=0.5, b1=20.0, b2=100.0, d0=0.0, d1=0.0)
    out["linear"].append(lsim_case("b_only", b_only, moves[:600]))
    # P loop without integrator and b2 != a2: rests at b2/a2 x_r (static error), default start there.
    static_error = dict(a1=120.0, a2=25000.0, a3=0.0, b0=0.0, b1=0.0, b2=20000.0, d0=0.0, d1=0.0)
    out["linear"].append(lsim_case("static_error", static_error, offset))
    out["linear"].append(lsim_case("ppi_estimated_off_equilibrium", MODELS["ppi_x_estimated"], offset, x0=100.02, ei0=-0.5))

    reversal = trajectory(0.0, [5.0, 1.0, 1.0005, 3.0], vmax=60.0, amax=800.0, dwell=0.08)
    out["friction"].append(friction_case("pid_reversal", MODELS["pid_x_actual"], reversal))
    out["friction"].append(friction_case("ppi_moves", MODELS["ppi_x_actual"], moves))
    out["friction"].append(friction_case("smc_moves", MODELS["smc_x_actual"], moves))
    out["friction"].append(friction_case("no_integrator_offset", MODELS["no_integrator"], offset))
    # Stiff for the sample rate (real pole at 368.8 Hz, omega ts = 2.3): the C++ series is split
    # into pieces; friction as estimated in Table 3.3.
    out["friction"].append(friction_case("ppi_estimated_moves", MODELS["ppi_x_estimated"], moves))
    inverted = dict(MODELS["pid_x_actual"], d0=-60.0, d1=90.0)
    out["friction"].append(friction_case("inverted_band", inverted, reversal[:800]))

    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as fh:
        json.dump(out, fh, separators=(",", ":"))
        fh.write("\n")
    print("wrote", os.path.normpath(OUT))


if __name__ == "__main__":
    main()
