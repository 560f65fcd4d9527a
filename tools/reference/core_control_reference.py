#!/usr/bin/env python3
"""Reference values for the control kernels of servotwin `core` (tests/core/test_state_space_algebra.cpp,
tests/core/test_norms.cpp).

How to run (from the repository root; numpy + scipy, written against numpy 1.24 / scipy 1.10 of
Debian 12 -- use the system interpreter, the pyenv python3 on PATH has no scipy):

    /usr/bin/python3 tools/reference/core_control_reference.py          # writes tests/data/core/control_reference.json
    /usr/bin/python3 tools/reference/core_control_reference.py -o FILE  # writes somewhere else

Deterministic (fixed systems, seeded generator); floats are written with Python's shortest
round-trip repr. Runs in a few seconds.

Contents and where each expected value comes from:
  systems        the test systems (A, B, C, D), built here (seeded random ones included).
  ss2tf          scipy.signal.ss2tf per input channel (num rows per output, den).
  dcgain         D - C A^-1 B with numpy.linalg.solve.
  freqresp       C (j w I - A)^-1 B + D with numpy.linalg.solve (LAPACK LU) per frequency;
                 discrete: C (z I - A)^-1 B + D at z = exp(j w ts).
  tustin         scipy.signal.cont2discrete(method="bilinear"); prewarped variant: the same call
                 with the effective period T = 2 tan(wp ts / 2) / wp (s -> (wp / tan(wp ts/2)) (z-1)/(z+1)).
  interconnect   frequency responses of series / parallel / feedback / append / lft_lower built from
                 the component responses with complex matrix algebra (Gb Ga, Ga + Gb,
                 (I - sign Gg Gh)^-1 Gg, diag, P11 + P12 K (I - P22 K)^-1 P21); no state-space
                 interconnection formula is used here.
  hinf           sup over omega of sigma_max(G(j omega)) by a dense log grid (20001 points over the
                 pole range widened 1e4 either side, plus omega = 0 and sigma_max(D) at infinity) and
                 scipy.optimize.minimize_scalar (bounded, in log omega, xatol 1e-12) from each of
                 the 8 largest grid maxima: a method independent of the Hamiltonian iteration.
  peak_delay     the same grid + refinement for |S(j w)| of a 4th-order loop with a transport delay
                 (no state space), and the bandwidth of its complementary sensitivity T: the first
                 dense-grid point below 10^(-3/20) |T(j w0)|, then scipy.optimize.brentq.
"""

import argparse
import json
import os

import numpy as np
import scipy
import scipy.optimize as opt
import scipy.signal as sig

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "..", "tests", "data", "core", "control_reference.json")


def mat(m):
    m = np.atleast_2d(np.asarray(m, dtype=float))
    return [[float(v) for v in row] for row in m]


def cmat(m):
    """Complex matrix as [[[re, im], ...], ...]."""
    m = np.atleast_2d(np.asarray(m, dtype=complex))
    return [[[float(v.real), float(v.imag)] for v in row] for row in m]


def ss_json(name, a, b, c, d, note):
    return dict(name=name, note=note, A=mat(a), B=mat(b), C=mat(c), D=mat(d))


# ---- systems ---------------------------------------------------------------------------------------

def two_mass(zeta=0.01):
    """Torque -> [motor velocity, load velocity] of a two-mass drive in SI units (J1 = 1e-3,
    J2 = 2e-3 kg m^2, k = 500 N m/rad), viscous friction to ground on both sides (so the rigid mode is
    a stable real pole) and shaft damping c chosen for the given modal damping. States
    [w1, theta1 - theta2, w2]."""
    j1, j2, k, b1, b2 = 1e-3, 2e-3, 500.0, 2e-3, 1e-3
    wn = np.sqrt(k * (j1 + j2) / (j1 * j2))
    c = zeta * 2.0 * j1 * j2 * wn / (j1 + j2)
    a = np.array([[-(b1 + c) / j1, -k / j1, c / j1],
                  [1.0, 0.0, -1.0],
                  [c / j2, k / j2, -(b2 + c) / j2]])
    b = np.array([[1.0 / j1], [0.0], [0.0]])
    cm = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    d = np.zeros((2, 1))
    return a, b, cm, d


def random_stable(rng, n, m, p, with_d=True, margin=0.3):
    """Random (A, B, C, D) with A shifted so that max Re(eig) = -margin."""
    a = rng.standard_normal((n, n))
    a -= (np.max(np.linalg.eigvals(a).real) + margin) * np.eye(n)
    b = rng.standard_normal((n, m))
    c = rng.standard_normal((p, n))
    d = 0.3 * rng.standard_normal((p, m)) if with_d else np.zeros((p, m))
    return a, b, c, d


def modal_chain(modes):
    """SISO sum of lightly damped modes r_i w_i^2 / (s^2 + 2 z_i w_i s + w_i^2) in modal form."""
    n = 2 * len(modes)
    a = np.zeros((n, n))
    b = np.zeros((n, 1))
    c = np.zeros((1, n))
    for i, (w, z, r) in enumerate(modes):
        a[2 * i:2 * i + 2, 2 * i:2 * i + 2] = [[0.0, 1.0], [-w * w, -2.0 * z * w]]
        b[2 * i + 1, 0] = w * w
        c[0, 2 * i] = r
    return a, b, c, np.zeros((1, 1))


def two_mass_shaft(zeta=0.01):
    """Torque -> shaft torque k (theta1 - theta2) of two_mass(zeta): peaks at the resonance
    (about J2 / ((J1 + J2) 2 zeta) = 33) far above its DC value b2 / (b1 + b2) = 1/3."""
    a, b, _, _ = two_mass(zeta)
    return a, b, np.array([[0.0, 500.0, 0.0]]), np.zeros((1, 1))


def random_resonant(rng, p, m):
    """Random 2x2-ish MIMO system with two lightly damped modes (zeta 0.03 at 1 rad/s, 0.05 at
    3.2 rad/s) and two real poles, hidden by a random similarity transform, random B, C and D."""
    blocks = [(1.0, 0.03), (3.2, 0.05)]
    n = 2 * len(blocks) + 2
    lam = np.zeros((n, n))
    for i, (w, z) in enumerate(blocks):
        lam[2 * i:2 * i + 2, 2 * i:2 * i + 2] = [[-z * w, w * np.sqrt(1 - z * z)], [-w * np.sqrt(1 - z * z), -z * w]]
    lam[n - 2, n - 2], lam[n - 1, n - 1] = -0.5, -7.0
    v = np.eye(n) + 0.4 * rng.standard_normal((n, n))
    a = v @ lam @ np.linalg.inv(v)
    b = rng.standard_normal((n, m))
    c = rng.standard_normal((p, n))
    d = 0.2 * rng.standard_normal((p, m))
    return a, b, c, d


def tf_ss(num, den):
    a, b, c, d = sig.tf2ss(num, den)
    return a, b, c, d


def build_systems():
    rng = np.random.default_rng(20261123)
    s = {}
    s["two_mass"] = (two_mass(0.01), "two-mass drive, SI units, zeta 0.01, torque -> [w_motor, w_load]")
    s["two_mass_shaft"] = (two_mass_shaft(0.01), "two-mass drive, torque -> shaft torque: resonance peak")
    s["mimo_random"] = (random_stable(rng, 6, 2, 2), "random stable 6 states, 2x2, D != 0 (seed 20261123)")
    s["mimo_resonant"] = (random_resonant(rng, 2, 2), "random 2x2, 6 states, modes zeta 0.03 at 1 rad/s and 0.05 at 3.2 rad/s, D != 0")
    s["mimo_3x2"] = (random_stable(rng, 5, 3, 2, with_d=True, margin=0.5), "random stable 5 states, 2 outputs x 3 inputs")
    s["relative_degree_3"] = (tf_ss([2.0, 3.0], [1.0, 4.0, 9.0, 10.0, 4.0]), "(2 s + 3)/(s^4 + 4 s^3 + 9 s^2 + 10 s + 4): relative degree 3")
    s["dc_peak"] = (tf_ss([3.0, 6.0], [1.0, 5.0, 11.0, 6.0]), "3 (s + 2)/((s + 1)(s + 2)(s + 3)) uncancelled: peak at DC")
    s["inf_peak"] = (tf_ss([2.0, 1.0, 0.6], [1.0, 1.2, 0.8]), "(2 s^2 + s + 0.6)/(s^2 + 1.2 s + 0.8): |G| rises to 2 at infinity")
    s["ten_state"] = (modal_chain([(40.0, 0.01, 1.0), (95.0, 0.015, -0.6), (170.0, 0.01, 0.4),
                                   (260.0, 0.02, 0.3), (410.0, 0.012, -0.2)]),
                      "5 lightly damped modes (zeta 0.01-0.02), 10 states: the benchmark system")
    return s


# ---- references ------------------------------------------------------------------------------------

def freq(a, b, c, d, s):
    n = a.shape[0]
    return c @ np.linalg.solve(s * np.eye(n) - a, b) + d


def sigma_max(g):
    return float(np.linalg.svd(np.atleast_2d(g), compute_uv=False)[0])


def ss2tf_cases(systems):
    out = []
    for name in ["two_mass", "mimo_3x2", "relative_degree_3", "ten_state"]:
        (a, b, c, d), _ = systems[name]
        for j in range(b.shape[1]):
            num, den = sig.ss2tf(a, b, c, d, input=j)
            out.append(dict(system=name, input=j, num=mat(num), den=[float(v) for v in den]))
    return out


def dcgain_cases(systems):
    out = []
    for name in ["two_mass", "mimo_random", "mimo_3x2", "dc_peak"]:
        (a, b, c, d), _ = systems[name]
        out.append(dict(system=name, G0=mat(d - c @ np.linalg.solve(a, b))))
    return out


def freqresp_cases(systems):
    out = []
    for name, omegas in [("two_mass", [0.0, 1.0, 500.0, 866.0, 870.0, 1e5]),
                         ("mimo_3x2", [0.0, 0.1, 1.0, 3.0, 100.0]),
                         ("ten_state", [10.0, 40.0, 95.0, 1000.0])]:
        (a, b, c, d), _ = systems[name]
        out.append(dict(system=name, omega=omegas, G=[cmat(freq(a, b, c, d, 1j * w)) for w in omegas]))
    return out


def tustin_cases(systems):
    out = []
    for name, ts, wp in [("two_mass", 1e-4, None), ("two_mass", 1e-3, 866.0), ("mimo_3x2", 0.05, None),
                         ("mimo_3x2", 0.05, 20.0), ("relative_degree_3", 0.1, 3.0)]:
        (a, b, c, d), _ = systems[name]
        t = ts if wp is None else 2.0 * np.tan(wp * ts / 2.0) / wp
        ad, bd, cd, dd, _ = sig.cont2discrete((a, b, c, d), t, method="bilinear")
        omegas = [0.3 * np.pi / ts, 0.9 * np.pi / ts] + ([wp] if wp is not None else [])
        gd = [cmat(freq(ad, bd, cd, dd, np.exp(1j * w * ts))) for w in omegas]
        out.append(dict(system=name, ts=ts, prewarp=wp, Ad=mat(ad), Bd=mat(bd), Cd=mat(cd), Dd=mat(dd),
                        omega=omegas, Gd=gd))
    return out


def interconnect_cases():
    rng = np.random.default_rng(7)
    g = random_stable(rng, 3, 2, 2, margin=0.4)          # forward path, 2x2
    h = random_stable(rng, 2, 2, 2, margin=0.8)          # feedback path, 2x2 with D
    a2 = random_stable(rng, 2, 2, 3, margin=0.6)         # 3 outputs x 2 inputs (series: g then a2)
    p = random_stable(rng, 4, 3, 3, margin=0.5)          # generalized plant: w (2) + u (1) -> z (2) + y (1)
    k = random_stable(rng, 2, 1, 1, margin=1.0)          # controller 1x1 with DK != 0
    omegas = [0.0, 0.2, 1.0, 2.5, 10.0, 100.0]
    series_, parallel_, fb_neg, fb_pos, append_, lft_ = [], [], [], [], [], []
    for w in omegas:
        s = 1j * w
        gg, hh, aa, pp, kk = (freq(*sys_, s) for sys_ in (g, h, a2, p, k))
        series_.append(cmat(aa @ gg))
        parallel_.append(cmat(gg + hh))
        fb_neg.append(cmat(np.linalg.solve(np.eye(2) + gg @ hh, gg)))
        fb_pos.append(cmat(np.linalg.solve(np.eye(2) - gg @ hh, gg)))
        app = np.zeros((4, 4), dtype=complex)
        app[:2, :2] = gg
        app[2:, 2:] = hh
        append_.append(cmat(app))
        p11, p12, p21, p22 = pp[:2, :2], pp[:2, 2:], pp[2:, :2], pp[2:, 2:]
        lft_.append(cmat(p11 + p12 @ kk @ np.linalg.solve(np.eye(1) - p22 @ kk, p21)))
    systems = {n: ss_json(n, *v, note) for n, v, note in [
        ("g", g, "forward path 3 states 2x2"), ("h", h, "feedback path 2 states 2x2"),
        ("a2", a2, "2 states, 3 outputs x 2 inputs"), ("p", p, "generalized plant 4 states, inputs [w1 w2 u], outputs [z1 z2 y]"),
        ("k", k, "controller 2 states 1x1")]}
    return dict(systems=systems, omega=omegas, series_g_a2=series_, parallel_g_h=parallel_,
                feedback_negative=fb_neg, feedback_positive=fb_pos, append_g_h=append_, lft_lower_p_k=lft_)


def refine_peak(gain, grid, values, top=8):
    """Largest local maxima of `values` on `grid`, each refined by bounded scalar minimisation in
    log omega between its neighbours."""
    best_value, best_omega = float(np.max(values)), float(grid[int(np.argmax(values))])
    interior = [i for i in range(len(grid))
                if (i == 0 or values[i] > values[i - 1]) and (i == len(grid) - 1 or values[i] >= values[i + 1])]
    interior.sort(key=lambda i: -values[i])
    for i in interior[:top]:
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        if lo <= 0.0:
            lo = hi * 1e-6
        r = opt.minimize_scalar(lambda x: -gain(np.exp(x)), bounds=(np.log(lo), np.log(hi)), method="bounded",
                                options=dict(xatol=1e-12, maxiter=500))
        if -r.fun > best_value:
            best_value, best_omega = float(-r.fun), float(np.exp(r.x))
    return best_value, best_omega


def hinf_reference(a, b, c, d):
    poles = np.linalg.eigvals(a)
    lo, hi = np.min(np.abs(poles)) * 1e-4, np.max(np.abs(poles)) * 1e4
    grid = np.logspace(np.log10(lo), np.log10(hi), 20001)
    gain = lambda w: sigma_max(freq(a, b, c, d, 1j * w))
    values = np.array([gain(w) for w in grid])
    value, omega = refine_peak(gain, grid, values)
    dc = gain(0.0)
    if dc >= value:
        value, omega = dc, 0.0
    sd = sigma_max(d)
    if sd >= value:
        value, omega = sd, float("inf")
    return value, omega


def hinf_cases(systems):
    out = []
    for name in ["two_mass", "two_mass_shaft", "mimo_random", "mimo_resonant", "mimo_3x2", "dc_peak", "inf_peak",
                 "ten_state", "relative_degree_3"]:
        (a, b, c, d), _ = systems[name]
        value, omega = hinf_reference(a, b, c, d)
        out.append(dict(system=name, value=value, omega=omega if np.isfinite(omega) else "inf"))
    return out


def delay_loop():
    """L(s) = K e^{-sT} (s + 2) / (s (s + 1)(s^2 + 2 z w s + w^2)): a velocity loop with a resonance
    and a transport delay. Returns (S, T) as functions of omega."""
    k_gain, delay, w, z = 2.5, 0.05, 12.0, 0.05
    num = k_gain * np.poly1d([1.0, 2.0])
    den = np.poly1d([1.0, 0.0]) * np.poly1d([1.0, 1.0]) * np.poly1d([1.0, 2.0 * z * w, w * w])

    def loop(omega):
        s = 1j * omega
        return num(s) / den(s) * np.exp(-s * delay)

    return (lambda om: 1.0 / (1.0 + loop(om))), (lambda om: loop(om) / (1.0 + loop(om))), \
        dict(k=k_gain, delay=delay, w=w, zeta=z, num=list(num.coeffs), den=list(den.coeffs))


def peak_delay_case():
    sens, comp, params = delay_loop()
    grid = np.logspace(-3, 3, 200001)
    mag_s = np.abs(sens(grid))
    value, omega = refine_peak(lambda w: abs(sens(w)), grid, mag_s)
    # Bandwidth of T referenced to |T(j 1e-3)| (the low end of the tests' grid).
    w0 = 1e-3
    level = abs(comp(w0)) * 10.0 ** (-3.0 / 20.0)
    mag_t = np.abs(comp(grid))
    i = int(np.argmax(mag_t < level))
    bw = opt.brentq(lambda w: abs(comp(w)) - level, grid[i - 1], grid[i], xtol=1e-15, rtol=1e-14)
    return dict(params=params, grid_first=w0, peak_S=value, peak_S_omega=omega, bandwidth_T=bw,
                T_at_grid_first=[float(comp(w0).real), float(comp(w0).imag)])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("-o", "--output", default=DEFAULT_OUT)
    args = parser.parse_args()
    systems = build_systems()
    data = dict(
        generator=dict(script="tools/reference/core_control_reference.py", numpy=np.__version__, scipy=scipy.__version__),
        systems=[ss_json(n, *v, note) for n, (v, note) in systems.items()],
        ss2tf=ss2tf_cases(systems),
        dcgain=dcgain_cases(systems),
        freqresp=freqresp_cases(systems),
        tustin=tustin_cases(systems),
        interconnect=interconnect_cases(),
        hinf=hinf_cases(systems),
        peak_delay=peak_delay_case(),
    )
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    with open(args.output, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    print("wrote", os.path.abspath(args.output))


if __name__ == "__main__":
    main()
