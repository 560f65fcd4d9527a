#!/usr/bin/env python3
"""Reference values for the LQG velocity and position compensators of the normalized two-mass plant
(module `tuning`, issue 7 §4; catalog C7.13 and example E29).

Writes tests/data/tuning/lqg_reference.json. Independent of the C++ code: the state-space models
are written out here from the equations of motion (catalog C7.13, with the viscous frictions of
C7.6), the Riccati equations are solved by scipy.linalg.solve_continuous_are, poles by
numpy.linalg.eigvals, peaks on a dense log grid refined by scipy.optimize.minimize_scalar.

Normalized plant (Im = 1, omega_z = 1): Il = k = r^2 - 1, b = 2 zeta_z (r^2 - 1), motor and load
viscous frictions bm, bl; the load torque Tl opposes the motion:
    w_m' = -(b + bm) w_m + b w_l - Ts + Tm
    Il w_l' = b w_m - (b + bl) w_l + Ts - Tl
    Ts' = k (w_m - w_l)

Velocity LQG (C7.13):
  LQR on x = [w_m, w_l, Ts, xi], xi' = -w_m (+ w* at run time), Q = diag(0, 20, kbw/c^2, 20),
  R = rho = kbw/c^2, c = r^2/2; u = -K x.
  Kalman filter on [w_m, w_l, Ts, Tl] (Tl constant), y = w_m, G = [[1,0],[0,0],[0,0],[0,1]],
  W = diag(1, 1), V = 0.1.
  Compensator (5 states [x_hat (4), xi], inputs [w*, y], output u):
    u = -[K1 K2 K3] x_hat[0:3] - K4 xi + kff w*
    x_hat' = Ae x_hat + Be u + L (y - Ce x_hat),   xi' = w* - y
  (with `raw` the term K1 uses y instead of x_hat[0]).
Position LQG (C7.13; the estimator model eq. 7.138 is missing from the source, defect 19, and is
reconstructed as the position model plus a constant load torque):
  LQR on x = [phi_m, w_m, phi_l, w_l, xi], xi' = -phi_m, Q = diag(1, 1, 20, 20, 5), R = kbw/c^2;
  Kalman filter on [phi_m, w_m, phi_l, w_l, Tl], y = phi_m, W = I5, V = 0.01.

Cases: E29 (r = 3, zeta_z = 0.01, kbw = 1) and the kbw sweep 0.1 / 10 of C7.13 [D], r = 2, and
r = 5 with viscous frictions.

Run:  /usr/bin/python3 tools/reference/tuning_lqg_reference.py   (numpy, scipy)
"""
import json
import math
import os

import numpy as np
from scipy import linalg, optimize

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "tuning", "lqg_reference.json")


def plant(r, zz, bm, bl):
    il = k = r * r - 1.0
    b = 2.0 * zz * (r * r - 1.0)
    a = np.array([[-(b + bm), b, -1.0], [b / il, -(b + bl) / il, 1.0 / il], [k, -k, 0.0]])
    bu = np.array([[1.0], [0.0], [0.0]])
    bt = np.array([[0.0], [-1.0 / il], [0.0]])
    return a, bu, bt, il, k, b


def lqr(a, b, q, rho):
    x = linalg.solve_continuous_are(a, b, q, np.array([[rho]]))
    return (b.T @ x) / rho


def kalman(a, c, w, v):
    y = linalg.solve_continuous_are(a.T, c.T, w, np.array([[v]]))
    return (y @ c.T) / v


def cplx(z):
    z = sorted(z, key=lambda p: (round(abs(p), 9), -p.imag))
    return [[float(p.real), float(p.imag)] for p in z]


def velocity_regulator(ap, bu, bt, r, kbw, integral_output):
    """C7.13's velocity regulator with the integral on output 0 (wm) or 1 (wl): the augmented
    (aa, ba), the estimator model's ae (plant + constant load torque), the gain and rho."""
    c = r * r / 2.0
    rho = kbw / c ** 2
    aa = np.zeros((4, 4))
    aa[:3, :3] = ap
    aa[3, integral_output] = -1.0
    ba = np.vstack([bu, [[0.0]]])
    kk = lqr(aa, ba, np.diag([0.0, 20.0, rho, 20.0]), rho)
    ae = np.zeros((4, 4))
    ae[:3, :3] = ap
    ae[:3, 3:4] = bt
    return aa, ba, ae, kk, rho


def velocity_case(r, zz, kbw, bm=0.0, bl=0.0, raw=False, mt=1.5):
    ap, bu, bt, il, k, b = plant(r, zz, bm, bl)
    aa, ba, ae, kk, rho = velocity_regulator(ap, bu, bt, r, kbw, 0)
    lqr_poles = np.linalg.eigvals(aa - ba @ kk)
    be = np.vstack([bu, [[0.0]]])
    ce = np.array([[1.0, 0.0, 0.0, 0.0]])
    g = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 1.0]])
    l = kalman(ae, ce, g @ np.eye(2) @ g.T, 0.1)
    kf_poles = np.linalg.eigvals(ae - l @ ce)

    def compensator(kff):
        kx = np.zeros((1, 4))
        kx[0, :3] = kk[0, :3]
        ky = 0.0
        if raw:
            ky = kk[0, 0]
            kx[0, 0] = 0.0
        k4 = kk[0, 3]
        # u = -kx xh - k4 xi - ky y + kff w*
        ac = np.zeros((5, 5))
        ac[:4, :4] = ae - be @ kx - l @ ce
        ac[:4, 4:5] = -be * k4
        bc = np.zeros((5, 2))
        bc[:4, 0:1] = be * kff
        bc[:4, 1:2] = l - be * ky
        bc[4, 0] = 1.0
        bc[4, 1] = -1.0
        cc = np.hstack([-kx, [[-k4]]])
        dc = np.array([[kff, -ky]])
        return ac, bc, cc, dc

    def closed_loop(kff):
        ac, bc, cc, dc = compensator(kff)
        # plant xp' = ap xp + bu u + bt tl, y = xp[0]; u = cc xc + dc [w*, y]
        cy = np.array([[1.0, 0.0, 0.0]])
        a = np.zeros((8, 8))
        a[:3, :3] = ap + bu @ dc[:, 1:2] @ cy
        a[:3, 3:] = bu @ cc
        a[3:, :3] = bc[:, 1:2] @ cy
        a[3:, 3:] = ac
        bref = np.vstack([bu * dc[0, 0], bc[:, 0:1]])
        bload = np.vstack([bt, np.zeros((5, 1))])
        return a, bref, bload

    def load_tracking_peak(kff):
        a, bref, _ = closed_loop(kff)
        cl = np.zeros((1, 8))
        cl[0, 1] = 1.0
        return peak(lambda w: (cl @ np.linalg.solve(1j * w * np.eye(8) - a, bref))[0, 0])

    a0, _, _ = closed_loop(0.0)
    ac0 = compensator(0.0)[0]
    peak0 = load_tracking_peak(0.0)
    kff_max = None
    if peak0 < mt:
        hi = 1.0
        while load_tracking_peak(hi) < mt and hi < 1e4:
            hi *= 2.0
        kff_max = optimize.brentq(lambda f: load_tracking_peak(f) - mt, 0.0, hi, xtol=1e-10) if hi < 1e4 else None
    ac, bc, cc, dc = compensator(0.0)
    return {
        "r": r, "zeta_z": zz, "kbw": kbw, "bm": bm, "bl": bl, "raw_motor_velocity": raw,
        "K": kk[0].tolist(), "lqr_poles": cplx(lqr_poles),
        "L": l[:, 0].tolist(), "kf_poles": cplx(kf_poles),
        "controller_poles": cplx(np.linalg.eigvals(ac0)),
        "closed_loop_poles": cplx(np.linalg.eigvals(a0)),
        "compensator": {"A": ac.tolist(), "B": bc.tolist(), "C": cc.tolist(), "D": dc.tolist()},
        "load_tracking_peak_kff0": peak0, "mt": mt, "kff_max": kff_max,
    }


def position_case(r, zz, kbw, bm=0.0, bl=0.0):
    il = k = r * r - 1.0
    b = 2.0 * zz * (r * r - 1.0)
    # [phi_m, w_m, phi_l, w_l]
    ap = np.array([[0.0, 1.0, 0.0, 0.0],
                   [-k, -(b + bm), k, b],
                   [0.0, 0.0, 0.0, 1.0],
                   [k / il, b / il, -k / il, -(b + bl) / il]])
    bu = np.array([[0.0], [1.0], [0.0], [0.0]])
    bt = np.array([[0.0], [0.0], [0.0], [-1.0 / il]])
    c = r * r / 2.0
    rho = kbw / c ** 2
    aa = np.zeros((5, 5))
    aa[:4, :4] = ap
    aa[4, 0] = -1.0
    ba = np.vstack([bu, [[0.0]]])
    kk = lqr(aa, ba, np.diag([1.0, 1.0, 20.0, 20.0, 5.0]), rho)
    ae = np.zeros((5, 5))
    ae[:4, :4] = ap
    ae[:4, 4:5] = bt
    ce = np.array([[1.0, 0.0, 0.0, 0.0, 0.0]])
    l = kalman(ae, ce, np.eye(5), 0.01)
    return {
        "r": r, "zeta_z": zz, "kbw": kbw, "bm": bm, "bl": bl,
        "K": kk[0].tolist(), "lqr_poles": cplx(np.linalg.eigvals(aa - ba @ kk)),
        "L": l[:, 0].tolist(), "kf_poles": cplx(np.linalg.eigvals(ae - l @ ce)),
    }


def load_side_case(r, zz, kbw, bm=0.0, bl=0.0):
    """C7.17's LQG with load feedback: regulator on [wm, wl, Ts, xi] with xi' = w* - wl and the
    velocity weights; Kalman filter on [wm, wl, Ts, Tl] measuring both velocities, W into wm and Tl
    (1, 1), V = diag(0.1, 0.1)."""
    ap, bu, bt, il, k, b = plant(r, zz, bm, bl)
    aa, ba, ae, kk, rho = velocity_regulator(ap, bu, bt, r, kbw, 1)
    ce = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
    w = np.diag([1.0, 0.0, 0.0, 1.0])
    v = 0.1 * np.eye(2)
    y = linalg.solve_continuous_are(ae.T, ce.T, w, v)
    l = y @ ce.T @ np.linalg.inv(v)
    return {
        "r": r, "zeta_z": zz, "kbw": kbw, "bm": bm, "bl": bl,
        "K": kk[0].tolist(), "lqr_poles": cplx(np.linalg.eigvals(aa - ba @ kk)),
        "L": l.tolist(), "kf_poles": cplx(np.linalg.eigvals(ae - l @ ce)),
    }


def modal_case(r, zz, kbw, modes):
    """C7.16's "extended model" velocity LQG: each higher mode (wz, zeta_z, wp, zeta_p) as the
    unit-DC-gain factor hf (s^2 + 2 zeta_z wz s + wz^2)/(s^2 + 2 zeta_p wp s + wp^2), hf = wp^2/wz^2,
    in series with the motor torque, realized here in observer form (hf + (c1 s + c0)/(s^2 + a1 s
    + a0)), a basis other than servotwin's: the gains differ by the basis, the pole sets do not."""
    ap, bu, bt, il, k, b = plant(r, zz, 0.0, 0.0)
    a, bu_x, bt_x, c_x = ap, bu, bt, np.array([[1.0, 0.0, 0.0]])
    for wz, zetaz, wp, zetap in modes:
        hf = wp * wp / (wz * wz)
        a1, a0 = 2.0 * zetap * wp, wp * wp
        c1, c0 = hf * 2.0 * zetaz * wz - hf * a1, hf * wz * wz - hf * a0
        af = np.array([[-a1, 1.0], [-a0, 0.0]])
        bf = np.array([[c1], [c0]])
        cf = np.array([[1.0, 0.0]])
        n = a.shape[0]
        big = np.zeros((n + 2, n + 2))
        big[:n, :n] = a
        big[:n, n:] = bu_x @ cf
        big[n:, n:] = af
        bu_x = np.vstack([bu_x * hf, bf])
        bt_x = np.vstack([bt_x, np.zeros((2, 1))])
        c_x = np.hstack([c_x, np.zeros((1, 2))])
        a = big
    n = a.shape[0]
    c = r * r / 2.0
    rho = kbw / c ** 2
    aa = np.zeros((n + 1, n + 1))
    aa[:n, :n] = a
    aa[n, :n] = -c_x[0]
    ba = np.vstack([bu_x, [[0.0]]])
    q = np.zeros(n + 1)
    q[1], q[2], q[n] = 20.0, rho, 20.0
    kk = lqr(aa, ba, np.diag(q), rho)
    ae = np.zeros((n + 1, n + 1))
    ae[:n, :n] = a
    ae[:n, n:n + 1] = bt_x
    be = np.vstack([bu_x, [[0.0]]])
    ce = np.hstack([c_x, [[0.0]]])
    g = np.zeros((n + 1, n + 1))
    g[0, 0] = 1.0
    g[n, n] = 1.0
    l = kalman(ae, ce, g, 0.1)
    kx = np.hstack([kk[:, :n], [[0.0]]])  # over [plant, Tl]: the load-torque estimate is not fed back
    k_xi = kk[0, n]
    ac = np.zeros((n + 2, n + 2))
    ac[:n + 1, :n + 1] = ae - be @ kx - l @ ce
    ac[:n + 1, n + 1:] = -be * k_xi
    bc = np.zeros((n + 2, 2))
    bc[:n + 1, 1:2] = l
    bc[n + 1, 0] = 1.0
    bc[n + 1, 1] = -1.0
    cc = np.hstack([-kx, [[-k_xi]]])
    # closed loop: plant x' = a x + bu_x u + bt_x tl, y = c_x x; u = cc xc (kff = 0, no D)
    m = n + n + 2
    acl = np.zeros((m, m))
    acl[:n, :n] = a
    acl[:n, n:] = bu_x @ cc
    acl[n:, :n] = bc[:, 1:2] @ c_x
    acl[n:, n:] = ac
    return {
        "r": r, "zeta_z": zz, "kbw": kbw, "modes": [list(mo) for mo in modes],
        "lqr_poles": cplx(np.linalg.eigvals(aa - ba @ kk)),
        "kf_poles": cplx(np.linalg.eigvals(ae - l @ ce)),
        "controller_poles": cplx(np.linalg.eigvals(ac)),
        "closed_loop_poles": cplx(np.linalg.eigvals(acl)),
    }


def peak(f):
    w = np.logspace(-3, 3, 200001)
    mags = np.array([abs(f(x)) for x in w[::50]])
    i = int(np.argmax(mags)) * 50
    lo, hi = w[max(i - 50, 0)], w[min(i + 50, len(w) - 1)]
    res = optimize.minimize_scalar(lambda lw: -abs(f(math.exp(lw))), bounds=(math.log(lo), math.log(hi)),
                                   method="bounded", options={"xatol": 1e-12})
    return float(max(-res.fun, mags.max()))


def main():
    velocity = [
        velocity_case(3.0, 0.01, 1.0),        # E29
        velocity_case(3.0, 0.01, 0.1),        # C7.13 [D] kbw sweep
        velocity_case(3.0, 0.01, 10.0),
        velocity_case(2.0, 0.02, 1.0),
        velocity_case(5.0, 0.01, 1.0, bm=0.05, bl=0.1),
        velocity_case(3.0, 0.01, 1.0, raw=True),
    ]
    position = [position_case(3.0, 0.01, 1.0), position_case(2.0, 0.02, 0.5, bm=0.05, bl=0.1)]
    load_side = [load_side_case(3.0, 0.01, 1.0), load_side_case(5.0, 0.01, 0.3, bm=0.05, bl=0.1)]
    modal = [modal_case(2.0, 0.02, 1.0, [(3.2, 0.01, 7.4, 0.005)]),
             modal_case(3.0, 0.01, 0.5, [(4.0, 0.02, 6.0, 0.01), (9.0, 0.01, 14.0, 0.02)])]
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump({"generator": "tools/reference/tuning_lqg_reference.py", "velocity": velocity, "position": position,
                   "load_side": load_side, "modal": modal}, f, indent=1)
    e29 = velocity[0]
    print("E29 K =", np.round(e29["K"], 3), "lqr |p| =", sorted(round(math.hypot(*p), 3) for p in e29["lqr_poles"]))
    print("E29 KF poles =", e29["kf_poles"])
    for v in velocity[:3]:
        mags = [math.hypot(*p) for p in v["lqr_poles"]]
        print("kbw", v["kbw"], "dominant |p| =", round(min(mags), 3), "controller poles", v["controller_poles"],
              "peak", round(v["load_tracking_peak_kff0"], 4), "kff_max", v["kff_max"])


if __name__ == "__main__":
    main()
