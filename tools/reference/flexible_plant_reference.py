#!/usr/bin/env python3
"""Reference values for the flexible plants (tests/machine/test_flexible_plant*.cpp).

Writes tests/data/machine/flexible_plant_reference.json. Everything is computed independently of
the C++ code, from the equations of motion M phi'' + B phi' + K phi = e1 T (catalog C3.12/C3.13):

* zoh_*: exact sampled responses, scipy.signal.cont2discrete(method="zoh") + dlsim, of chains
  assembled here in second-order form (x = [phi; w]) with an optional current-loop lag state;
* modes: scipy.linalg.eigh(K, M) (generalized symmetric eigenproblem) with mass-normalised shapes
  and modal damping phi^T B phi / (2 omega) for a Rayleigh-damped chain;
* tf_*: transfer-function plants, numpy.polymul products of the printed factors (E14, E37), their
  ZOH responses (realised as a cascade of the printed low-order factors) and pole
  frequencies/dampings from numpy.roots;
* backlash_sine: a two-mass chain with a dead-zone shaft driven by a sinusoidal torque, integrated
  by scipy.integrate.solve_ivp (DOP853, rtol 1e-11, max_step ts/200) on the discontinuous
  right-hand side, sampled at k ts;
* coulomb_slide: a sliding two-mass chain whose load carries constant Coulomb friction (the
  velocity never reverses), solved by ZOH with the friction as a constant input.

Run:  /usr/bin/python3 tools/reference/flexible_plant_reference.py
"""

import json
import math
import os

import numpy as np
import scipy.integrate as si
import scipy.linalg as sla
import scipy.signal as ss

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "machine",
                   "flexible_plant_reference.json")


def chain_matrices(inertia, stiffness, damping, viscous):
    n = len(inertia)
    M = np.diag(inertia)
    K = np.zeros((n, n))
    B = np.diag(viscous).astype(float)
    for s in range(n - 1):
        for (i, j, v) in ((s, s, 1), (s + 1, s + 1, 1), (s, s + 1, -1), (s + 1, s, -1)):
            K[i, j] += v * stiffness[s]
            B[i, j] += v * damping[s]
    return M, B, K


def chain_state_space(inertia, stiffness, damping, viscous, lag=0.0):
    """x = [phi_1..phi_n, w_1..w_n, (lag torque)], input torque command; outputs
    [phi_1, w_1, phi_n, w_n]."""
    M, B, K = chain_matrices(inertia, stiffness, damping, viscous)
    n = len(inertia)
    Minv = np.linalg.inv(M)
    N = 2 * n + (1 if lag > 0 else 0)
    A = np.zeros((N, N))
    A[:n, n:2 * n] = np.eye(n)
    A[n:2 * n, :n] = -Minv @ K
    A[n:2 * n, n:2 * n] = -Minv @ B
    Bu = np.zeros((N, 1))
    if lag > 0:
        A[n, 2 * n] = 1.0 / inertia[0]
        A[2 * n, 2 * n] = -1.0 / lag
        Bu[2 * n, 0] = 1.0 / lag
    else:
        Bu[n, 0] = 1.0 / inertia[0]
    C = np.zeros((4, N))
    C[0, 0] = 1
    C[1, n] = 1
    C[2, n - 1] = 1
    C[3, 2 * n - 1] = 1
    return A, Bu, C, np.zeros((4, 1))


def zoh_response(sys, ts, u):
    d = ss.cont2discrete(sys, ts, method="zoh")
    _, y, _ = ss.dlsim((d[0], d[1], d[2], d[3], ts), np.append(u, 0.0))
    # The plant's step k returns the state after the period: dlsim's sample k + 1.
    return y[1:]


def zoh_case(name, inertia, stiffness, damping, viscous, lag, ts, samples, seed):
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.0, 1.0, samples)
    y = zoh_response(chain_state_space(inertia, stiffness, damping, viscous, lag), ts, u)
    return dict(inertia=inertia, stiffness=stiffness, damping=damping, viscous=viscous, current_lag=lag,
                ts=ts, u=u.tolist(), motor_position=y[:, 0].tolist(), motor_velocity=y[:, 1].tolist(),
                load_position=y[:, 2].tolist(), load_velocity=y[:, 3].tolist())


def modes_case():
    inertia = [0.5, 2.0, 0.25, 1.5]
    stiffness = [400.0, 150.0, 900.0]
    alpha, beta = 0.3, 2e-3  # Rayleigh: B = alpha M + beta K
    M, _, K = chain_matrices(inertia, stiffness, [0.0] * 3, [0.0] * 4)
    B = alpha * M + beta * K
    w2, phi = sla.eigh(K, M)
    omegas = np.sqrt(np.clip(w2, 0.0, None))
    omegas[0] = 0.0
    shapes = []
    zetas = []
    for i in range(len(inertia)):
        v = phi[:, i] / math.sqrt(phi[:, i] @ M @ phi[:, i])
        first = next(x for x in v if abs(x) > 1e-9 * np.max(np.abs(v)))
        if first < 0:
            v = -v
        shapes.append(v.tolist())
        zetas.append(0.0 if omegas[i] == 0 else float(v @ B @ v / (2 * omegas[i])))
    return dict(inertia=inertia, stiffness=stiffness, alpha=alpha, beta=beta,
                shaft_damping=[beta * k for k in stiffness], viscous=[alpha * m for m in inertia],
                omega=omegas.tolist(), shapes=shapes, zeta=zetas)


def quad(w, z):
    return np.array([1.0, 2 * z * w, w * w])


def modal(roots):
    return [dict(omega=float(abs(r)), zeta=float(-r.real / abs(r))) for r in roots]


def cascade(sections):
    """Series connection of tf2ss realizations of low-order sections: better conditioned than
    tf2ss of the expanded product (whose coefficients span many decades for the test bed)."""
    A, B, C, D = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.eye(1)
    for n, d in sections:
        a, b, c, dd = ss.tf2ss(n, d)
        N, M = A.shape[0], a.shape[0]
        A = np.block([[A, np.zeros((N, M))], [b @ C, a]])
        B = np.vstack([B, b @ D])
        C = np.hstack([dd @ C, c])
        D = dd @ D
    return A, B, C, D


def tf_case(name, sections, ts, samples, seed, lag=0.0):
    if lag > 0:
        sections = sections + [([1.0], [lag, 1.0])]
    num, den = np.array([1.0]), np.array([1.0])
    for n, d in sections:
        num, den = np.polymul(num, n), np.polymul(den, d)
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.0, 1.0, samples)
    y = zoh_response(cascade(sections), ts, u)
    poles = np.roots(den)
    return dict(name=name, num=list(map(float, num)), den=list(map(float, den)), ts=ts, current_lag=lag,
                u=u.tolist(), y=y[:, 0].tolist(),
                poles=sorted(modal([p for p in poles if p.imag >= 0]), key=lambda m: m["omega"]),
                zeros=sorted(modal([z for z in np.roots(num) if z.imag >= 0]), key=lambda m: m["omega"]))


def presets():
    out = {}
    # E37 configuration 1 and 2: tau1 a pole location (catalog defect 29), tau2 the time constant
    # of the lag 1/(tau2 s + 1) (flexible_presets.hpp says why).
    num = 544.6 * np.polymul(quad(35.3, 0.19), quad(114.6, 0.11))
    den = np.polymul(np.polymul(np.polymul([1, 0.16], quad(70.8, 0.02)), quad(260.1, 0.005)), [0.0038, 1])
    out["testbed-1"] = dict(num=num.tolist(), den=den.tolist())
    num = 454.5 * quad(49.9, 0.24)
    den = np.polymul(np.polymul([1, 0.15], quad(254.0, 0.02)), [0.0022, 1])
    out["testbed-2"] = dict(num=num.tolist(), den=den.tolist())
    num = np.polymul([1, 0.06339, 0.06057], [1, 0.1129, 2.064])
    den = np.polymul(np.polymul([1, 0.04544], [1, 0.04541, 0.9985]), [1, 0.9854, 9.12])
    out["rfid-demo"] = dict(num=num.tolist(), den=den.tolist())
    g = 9.80665
    out["gantry-crane"] = dict(num=[-4.22 ** 2 / g, 0.0], den=quad(4.22, 0.0079).tolist())
    out["table-5.1"] = dict(num=[0.5, 0.06, 0.5], den=[1.0, 1.1, 9.18, 1.8])
    return out


def backlash_rhs(p):
    im, il, k, b, bm, bl, D, amp, w = (p[x] for x in ("im", "il", "k", "b", "bm", "bl", "D", "amp", "w"))

    def rhs(t, x):
        pm, pl, vm, vl = x
        u = pm - pl
        du = vm - vl
        if abs(u) <= D / 2:
            T = 0.0
        else:
            T = k * (u - math.copysign(D / 2, u)) + b * du
        torque = amp * math.sin(w * t)
        return [vm, vl, (torque - T - bm * vm) / im, (T - bl * vl) / il]
    return rhs


def backlash_case():
    p = dict(im=0.01, il=0.02, k=200.0, b=0.05, bm=0.001, bl=0.002, D=0.02, amp=0.5, w=2 * math.pi * 7.0)
    ts, samples = 1e-3, 600
    rhs = backlash_rhs(p)
    # The torque is a continuous function of time but the regime switches are discontinuous in the
    # state: integrate sample by sample with a small maximum step and tight tolerances.
    x = np.zeros(4)
    out = {k: [] for k in ("motor_position", "load_position", "motor_velocity", "load_velocity")}
    u = []
    for kk in range(samples):
        # The plant holds the command over each period: sample the sine at the period start.
        t0 = kk * ts
        hold = p["amp"] * math.sin(p["w"] * t0)
        u.append(hold)

        def held(t, y, hold=hold):
            dy = rhs(t, y)
            dy[2] += (hold - p["amp"] * math.sin(p["w"] * t)) / p["im"]
            return dy
        sol = si.solve_ivp(held, (t0, t0 + ts), x, method="DOP853", rtol=1e-11, atol=1e-14, max_step=ts / 200)
        x = sol.y[:, -1]
        out["motor_position"].append(float(x[0]))
        out["load_position"].append(float(x[1]))
        out["motor_velocity"].append(float(x[2]))
        out["load_velocity"].append(float(x[3]))
    return dict(params=p, ts=ts, u=u, **out)


def coulomb_case():
    inertia, stiffness, damping, viscous = [0.02, 0.05], [300.0], [0.1], [0.0, 0.0]
    ts, samples, tc = 1e-3, 400, 0.2
    # Constant torque 1.0 plus an initial load velocity 5 rad/s in +: the load keeps moving in +
    # (checked below), so its friction is the constant -tc throughout.
    M, B, K = chain_matrices(inertia, stiffness, damping, viscous)
    A, Bu, C, D = chain_state_space(inertia, stiffness, damping, viscous)
    Bf = np.zeros((4, 2))
    Bf[:, 0] = Bu[:, 0]
    Bf[3, 1] = 1.0 / inertia[1]
    d = ss.cont2discrete((A, Bf, C, np.zeros((4, 2))), ts, method="zoh")
    x0 = np.array([0.0, 0.0, 5.0, 5.0])
    u = np.column_stack([np.full(samples + 1, 1.0), np.full(samples + 1, -tc)])
    _, y, _ = ss.dlsim((d[0], d[1], d[2], d[3], ts), u, x0=x0)
    assert np.min(y[:, 3]) > 0.1, "the load must not stop in this case"
    y = y[1:]
    return dict(inertia=inertia, stiffness=stiffness, damping=damping, coulomb=tc, ts=ts, torque=1.0,
                initial_velocity=5.0, motor_velocity=y[:, 1].tolist(), load_position=y[:, 2].tolist(),
                load_velocity=y[:, 3].tolist())


def main():
    data = dict(
        zoh_two_mass=zoh_case("two-mass", [0.004815, 0.005085], [563.9], [0.0677], [2e-4, 1e-4], 0.0,
                              1.0 / 8000, 400, 11),
        zoh_chain_lag=zoh_case("chain", [1.0, 0.4, 2.5], [50.0, 120.0], [0.2, 0.05], [0.1, 0.0, 0.3], 0.02,
                               0.01, 300, 12),
        zoh_rigid=zoh_case("rigid", [0.3], [], [], [0.15], 0.0, 0.005, 100, 13),
        modes=modes_case(),
        tf_rfid_demo=tf_case("rfid-demo", [([1.0], [1, 0.04544]), ([1, 0.06339, 0.06057], [1, 0.04541, 0.9985]),
                                           ([1, 0.1129, 2.064], [1, 0.9854, 9.12])],
                             0.1, 300, 14),
        tf_testbed2_lag=tf_case("testbed-2+lag", [([454.5], [1, 0.15]), (quad(49.9, 0.24), quad(254.0, 0.02)),
                                                  ([1.0], [0.0022, 1])], 0.0005, 400, 15, lag=1e-3),
        presets=presets(),
        backlash_sine=backlash_case(),
        coulomb_slide=coulomb_case(),
    )
    with open(OUT, "w") as f:
        json.dump(data, f, indent=1)
    print("wrote", os.path.normpath(OUT))


if __name__ == "__main__":
    main()
