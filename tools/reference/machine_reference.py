#!/usr/bin/env python3
"""Reference values for the machine module's tests (tests/machine/*.cpp).

Writes tests/data/machine/machine_reference.json. Everything here is computed independently of
the C++ code: scipy.signal.cont2discrete for the zero-order-hold plant, scipy.signal.place_poles
for the state feedback, scipy.linalg.solve_discrete_are for the Kalman filter, a plain Python loop
for the controllers' difference equations, and a Python transcription of std::mt19937_64 for the
encoder noise.

Run:  /usr/bin/python3 tools/reference/machine_reference.py
"""

import json
import math
import os

import numpy as np
import scipy.linalg as sla
import scipy.optimize as sopt
import scipy.signal as ss

TS = 1e-3
J = 0.1      # N s^2/mm (100 kg)
K = 100.0    # N/V
OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "machine", "machine_reference.json")


# ---------------------------------------------------------------------------------------------
# Plant: exact ZOH of x'' = -a x' + (K/J) u - d  (states x, v; inputs u, d)
# ---------------------------------------------------------------------------------------------
def zoh_plant(a, kj, ts):
    A = np.array([[0.0, 1.0], [0.0, -a]])
    B = np.array([[0.0, 0.0], [kj, -1.0]])
    C = np.array([[1.0, 0.0]])
    D = np.zeros((1, 2))
    Ad, Bd, _, _, _ = ss.cont2discrete((A, B, C, D), ts, method="zoh")
    return Ad, Bd


def plant_numerator(Ad, b):
    """[1 0] adj(zI - Ad) b = b0 (z - Ad11) + Ad01 b1 (the plant is upper triangular)."""
    return np.array([b[0], Ad[0, 1] * b[1] - b[0] * Ad[1, 1]])


def plant_zero(a, ts):
    Ad, Bd = zoh_plant(a, 1.0, ts)
    num = plant_numerator(Ad, Bd[:, 0])
    return -num[1] / num[0]


# ---------------------------------------------------------------------------------------------
# Presets derived from thesis Tables 3.3-3.5 (independent transcription of the derivation)
# ---------------------------------------------------------------------------------------------
def pid_x():
    a1, a2, a3, b1 = 192.65, 44356.23, 316830.21, 190.10
    return dict(kind="pid", B=J * (a1 - b1), kp=a2 * J / K, ki=a3 * J / K, kd=b1 * J / K)


def ppi_x():
    a1, a2, a3, b2 = 372.76, 62009.83, 1527104.87, 11106.33
    kp = a3 / (a2 - b2)
    kv = b2 / kp * J / K
    ki = (a2 - b2) * J / K
    return dict(kind="ppi", B=J * (a1 - b2 / kp), kp=kp, kv=kv, ki=ki)


def smc_x():
    a1, a2, a3 = 390.10, 57029.44, 3801962.50
    bj = 192.65 - 190.10
    lam = -sopt.brentq(lambda s: ((s + a1) * s + a2) * s + a3, -1000.0, 0.0, xtol=1e-14)
    alpha = a1 - lam
    beta = a3 / lam
    return dict(kind="smc", B=J * bj, lam=lam, ks=(alpha - bj) * J / K, rho=beta * J / K)


def simulate_pid_family(c, cmd, ts):
    """Ideal loop: exact ZOH plant + the documented difference equations (axis_config.hpp)."""
    a = c["B"] / J
    Ad, Bd = zoh_plant(a, K / J, ts)
    n = len(cmd)
    r = np.concatenate([[cmd[0]], cmd, [cmd[-1]]])  # r[k+1] = x_r(k)
    x = np.zeros(2)
    y_prev = 0.0
    integ = 0.0
    out = []
    for k in range(n):
        y = x[0]
        out.append(y)
        xr_prev, xr, xr_next = r[k], r[k + 1], r[k + 2]
        rv = (xr_next - xr_prev) / (2 * ts)
        ra = (xr_next - 2 * xr + xr_prev) / ts**2
        mv = (y - y_prev) / ts
        y_prev = y
        e = xr - y
        if c["kind"] == "pid":
            integ += ts * e
            u = c["kp"] * e + c["ki"] * integ + c["kd"] * (rv - mv)
        elif c["kind"] == "ppi":
            ev = c["kp"] * e - mv
            integ += ts * ev
            u = c["kv"] * ev + c["ki"] * integ
        else:
            ed = rv - mv
            s = ed + c["lam"] * e
            integ += ts * c["rho"] * s
            u = (J * (ra + c["lam"] * ed) + c["B"] * (rv + c["lam"] * e)) / K + c["ks"] * s + integ
        x = Ad @ x + Bd[:, 0] * u
    return out


# ---------------------------------------------------------------------------------------------
# Ball-screw pole placement + Kalman filter + ZPETC (thesis 3.4.2)
# ---------------------------------------------------------------------------------------------
def ballscrew_design(delay, wn_hz=30.0, zeta=0.7, W=1e9, R=1e-6, ts=TS):
    z1_target = -0.99937
    a = sopt.brentq(lambda a: plant_zero(a, ts) - z1_target, 1e-3, 100.0, xtol=1e-14)
    kj = K / J
    Ad, Bd = zoh_plant(a, kj, ts)
    gu, gd = Bd[:, 0], -Bd[:, 1]  # disturbance acceleration enters as -gd d
    if delay == 0:
        Phi, Gam, Gd = Ad, gu, gd
    else:
        Phi = np.zeros((3, 3))
        Phi[:2, :2] = Ad
        Phi[:2, 2] = gu
        Gam = np.array([0.0, 0.0, 1.0])
        Gd = np.concatenate([gd, [0.0]])
    n = Phi.shape[0]
    wn = 2 * math.pi * wn_hz
    s = complex(-zeta * wn, wn * math.sqrt(1 - zeta**2))
    zp = np.exp(s * ts)
    poles = [zp, np.conj(zp)] + [0.0] * delay
    L = ss.place_poles(Phi, Gam.reshape(-1, 1), poles).gain_matrix[0]
    Acl = Phi - np.outer(Gam, L)
    N = 1.0 / np.linalg.solve(np.eye(n) - Acl, Gam)[0]
    # Kalman filter on [xi, d]
    na = n + 1
    Pa = np.zeros((na, na))
    Pa[:n, :n] = Phi
    Pa[:n, n] = -Gd
    Pa[n, n] = 1.0
    Ga = np.concatenate([Gam, [0.0]])
    C = np.zeros((1, na))
    C[0, 0] = 1.0
    Q = np.zeros((na, na))
    Q[n, n] = W * ts
    # scipy's DARE in its control form with A -> Pa', B -> C' gives the filter covariance.
    P = sla.solve_discrete_are(Pa.T, C.T, Q, np.array([[R]]))
    M = P @ C.T / (C @ P @ C.T + R)
    M = M[:, 0]
    obs = np.linalg.eigvals(Pa @ (np.eye(na) - np.outer(M, C[0])))
    # ZPETC taps: A(z)(1 - z1 z) / (B+ (1 - z1)^2)
    num = plant_numerator(Ad, gu)  # the delay adds a pole at 0, not a zero
    b_plus = N * num[0]
    z1 = -num[1] / num[0]
    Apoly = np.real(np.poly(poles))
    taps = np.convolve(Apoly, [-z1, 1.0]) / (b_plus * (1 - z1) ** 2)
    return dict(a=a, Phi=Phi, Gam=Gam, Gd=Gd, L=L, N=N, Pa=Pa, Ga=Ga, P=P, M=M, obs=obs, z1=z1, zp=zp,
                taps=taps, Apoly=Apoly, preview=n)


def simulate_ballscrew(d, cmd, ts=TS):
    """Ideal loop: plant + Kalman current estimator + pole placement + ZPETC, plain loop."""
    a = d["a"]
    Ad, Bd = zoh_plant(a, K / J, ts)
    P = d["preview"]
    r = np.concatenate([[cmd[0]], cmd, [cmd[-1]] * P])  # r[k+1] = x_r(k)
    n = d["Phi"].shape[0]
    x = np.zeros(2)
    xh = np.zeros(n + 1)
    ubuf = 0.0
    out = []
    delay = n - 2
    for k in range(len(cmd)):
        y = x[0]
        out.append(y)
        xr_star = sum(d["taps"][j] * r[k + 1 + P - j] for j in range(len(d["taps"])))
        xh = xh + d["M"] * (y - xh[0])
        u = d["N"] * xr_star - d["L"] @ xh[:n] + (J / K) * xh[n]
        xh = d["Pa"] @ xh + d["Ga"] * u
        applied = u if delay == 0 else ubuf
        ubuf = u
        x = Ad @ x + Bd[:, 0] * applied
    return out


def ballscrew_frf(d, omega, ts=TS):
    """Tracking x/x_r (command preview included) and disturbance x/d of the ideal PP+KF+ZPETC loop,
    solved in the frequency domain from the difference equations (delay 0)."""
    Ad, Bd = zoh_plant(d["a"], K / J, ts)
    z = np.exp(1j * omega * ts)
    P = d["preview"]
    xr_star = sum(d["taps"][j] * z ** (P - j) for j in range(len(d["taps"])))
    M, Pa, Ga = d["M"], d["Pa"], d["Ga"]
    kc = np.concatenate([d["L"], [-J / K]])
    imc = np.eye(3) - np.outer(M, [1.0, 0.0, 0.0])
    # unknowns [x, v, xh(k|k-1) (3)]; u = N x_r* - kc (imc xh + M x)
    urow = np.zeros(5)
    urow[0] = -kc @ M
    urow[2:] = -kc @ imc
    A = np.zeros((5, 5))
    A[:2, :2] = Ad
    A[:2, :] += np.outer(Bd[:, 0], urow)
    A[2:, 2:] = Pa @ imc
    A[2:, 0] += Pa @ M
    A[2:, :] += np.outer(Ga, urow)
    b = np.zeros((5, 2), complex)
    b[:2, 0] = Bd[:, 0] * d["N"] * xr_star
    b[2:, 0] = Ga * d["N"] * xr_star
    b[:2, 1] = Bd[:, 1]
    X = np.linalg.solve(z * np.eye(5) - A, b)
    return X[0, 0], X[0, 1]


def eq33_fit(d, f_min=0.1, f_max=125.0, points=200):
    """Nonlinear least squares (scipy) of Eq. 3.3 to the loop: tracking error + relative
    disturbance error, the objective the C++ Sanathanan-Koerner fit approximately minimizes."""
    w = 2 * math.pi * np.logspace(math.log10(f_min), math.log10(f_max), points)
    s = 1j * w
    TG = np.array([ballscrew_frf(d, x) for x in w])
    T, G = TG[:, 0], TG[:, 1]

    def residual(th):
        a1, a2, a3, b0, b1, b2 = th
        D = ((s + a1) * s + a2) * s + a3
        r1 = (((b0 * s + b1) * s + b2) * s + a3) / D - T
        r2 = (-s / D - G) / np.abs(G)
        return np.concatenate([r1.real, r1.imag, r2.real, r2.imag])

    start = np.array([450.0, 1.3e5, 1.2e7, 1.0, 450.0, 1.3e5])
    r = sopt.least_squares(residual, start, x_scale=np.abs(start), xtol=1e-14, ftol=1e-14, gtol=1e-14)
    return dict(coefficients=r.x.tolist(), cost=float(np.sum(r.fun ** 2)), f_min=f_min, f_max=f_max,
                points=points)


# ---------------------------------------------------------------------------------------------
# Encoder noise: std::mt19937_64 + splitmix64 seeding + Box-Muller (simulator.hpp)
# ---------------------------------------------------------------------------------------------
MASK = (1 << 64) - 1


class MT19937_64:
    def __init__(self, seed):
        self.mt = [0] * 312
        self.mt[0] = seed & MASK
        for i in range(1, 312):
            self.mt[i] = (6364136223846793005 * (self.mt[i - 1] ^ (self.mt[i - 1] >> 62)) + i) & MASK
        self.idx = 312

    def __call__(self):
        if self.idx >= 312:
            for i in range(312):
                x = (self.mt[i] & 0xFFFFFFFF80000000) | (self.mt[(i + 1) % 312] & 0x7FFFFFFF)
                xa = x >> 1
                if x & 1:
                    xa ^= 0xB5026F5AA96619E9
                self.mt[i] = self.mt[(i + 156) % 312] ^ xa
            self.idx = 0
        y = self.mt[self.idx]
        self.idx += 1
        y ^= (y >> 29) & 0x5555555555555555
        y ^= (y << 17) & 0x71D67FFFEDA60000
        y ^= (y << 37) & 0xFFF7EEE000000000
        y ^= y >> 43
        return y & MASK


def splitmix64(x):
    x = (x + 0x9E3779B97F4A7C15) & MASK
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & MASK
    return x ^ (x >> 31)


def gaussians(seed, stream, count):
    eng = MT19937_64(splitmix64(seed ^ ((0x9E3779B97F4A7C15 * (stream + 1)) & MASK)))
    out = []
    while len(out) < count:
        u1 = ((eng() >> 11) + 0.5) * 2.0**-53
        u2 = ((eng() >> 11) + 0.5) * 2.0**-53
        r = math.sqrt(-2.0 * math.log(u1))
        th = 2.0 * math.pi * u2
        out += [r * math.cos(th), r * math.sin(th)]
    return out[:count]


def main():
    # Sanity check of the MT transcription against the C++ standard's required 10000th value.
    eng = MT19937_64(5489)
    for _ in range(9999):
        eng()
    assert eng() == 9981545732273789042

    ref = {"generator": "tools/reference/machine_reference.py"}

    # Commands: a smoothed step and a swept sine, 0.4 s at 1 kHz.
    t = np.arange(400) * TS
    step = np.where(t >= 0.01, 1.0, 0.0)
    sweep = 0.5 * np.sin(2 * math.pi * (2.0 * t + 0.5 * 60.0 * t**2))  # 2 Hz -> 26 Hz
    sweep[:5] = 0.0
    ref["commands"] = {"step": step.tolist(), "sweep": sweep.tolist()}

    ref["pid_family"] = {}
    for name, c in (("fadal-pid", pid_x()), ("fadal-ppi", ppi_x()), ("fadal-smc", smc_x())):
        ref["pid_family"][name] = {
            "params": {k: v for k, v in c.items() if k != "kind"},
            "step": simulate_pid_family(c, step, TS),
            "sweep": simulate_pid_family(c, sweep, TS),
        }

    ref["ballscrew"] = {}
    for delay in (0, 1):
        d = ballscrew_design(delay)
        dare_residual = np.max(np.abs(
            d["Pa"] @ d["P"] @ d["Pa"].T
            - d["Pa"] @ d["P"][:, :1] @ d["P"][:1, :] @ d["Pa"].T / (d["P"][0, 0] + 1e-6)
            + np.diag([0.0] * (len(d["M"]) - 1) + [1e9 * TS]) - d["P"]))
        assert dare_residual < 1e-9 * max(1.0, np.max(np.abs(d["P"]))), dare_residual
        entry = {
            "damping_over_inertia": d["a"],
            "plant_zero": d["z1"],
            "z_pole": [d["zp"].real, d["zp"].imag],
            "feedback": d["L"].tolist(),
            "reference_gain": d["N"],
            "kalman_gain": d["M"].tolist(),
            "covariance": d["P"].tolist(),
            "observer_poles_abs": sorted(np.abs(d["obs"]).tolist()),
            "zpetc_taps": d["taps"].tolist(),
            "closed_loop_den": d["Apoly"].tolist(),
            "preview": d["preview"],
        }
        if delay == 0:
            entry["step"] = simulate_ballscrew(d, step)
            entry["sweep"] = simulate_ballscrew(d, sweep)
            entry["frf_check"] = []
            for f_hz in (0.5, 5.0, 30.0, 100.0):
                T, G = ballscrew_frf(d, 2 * math.pi * f_hz)
                entry["frf_check"].append([f_hz, T.real, T.imag, G.real, G.imag])
            entry["eq33_fit"] = eq33_fit(d)
        ref["ballscrew"]["delay%d" % delay] = entry

    ref["noise"] = {
        "seed1_stream0": gaussians(1, 0, 16),
        "seed1_stream1": gaussians(1, 1, 16),
        "seed42_stream0": gaussians(42, 0, 16),
    }

    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(ref, f, indent=1)
    print("wrote", os.path.normpath(OUT))


if __name__ == "__main__":
    main()
