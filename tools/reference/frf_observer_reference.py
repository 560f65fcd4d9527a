#!/usr/bin/env python3
"""Reference values for the servotwin real-time identification tests (tests/frf/test_observer*,
tests/frf/test_rfid_block*, tests/core/test_riccati.cpp).

How to run (from the repository root; needs numpy and scipy -- written against numpy 1.24 /
scipy 1.10 as shipped by Debian 12; use /usr/bin/python3 if another python3 comes first on PATH):

    /usr/bin/python3 tools/reference/frf_observer_reference.py          # writes tests/data/frf/frf_observer_reference.json
    /usr/bin/python3 tools/reference/frf_observer_reference.py -o FILE

Deterministic (fixed inputs, seeded generator). Floats are written with Python's shortest
round-trip repr.

Contents and where each expected value comes from:
  care         scipy.linalg.solve_continuous_are(a, b, q, r) for the harmonic observer's
               Kalman-Bucy problem (a = A_o(1)^T, b = C_o^T, q = W, r = V, dissertation C5.4) and for
               seeded random control problems (one unstable, several inputs).
  kalman       k(1) = Y C_o^T / V for the document's weights W and V in {0.5, 0.06, 0.02, 0.0085,
               0.005}, Y from solve_continuous_are; the J indices (peak gains in dB of the output
               estimate F_yhat_y, the DC channel and the five "sin" channels) from
               scipy.signal.freqresp on a 40001-point log grid over [1e-2, 1e3] rad/s, refined by
               scipy.optimize.minimize_scalar around the grid maximum; the -3 dB bandwidth of
               F_yhat_y above the 5th harmonic (relative to omega).
  kalman_v_sweep  J_yhat (dB, same method) for 13 log-spaced V over [0.005, 0.5]: the document's
               bound "J_yhat <= 2.35 dB" holds at its five table values but the supremum over the
               interval is ~2.42 dB near V = 0.34.
  butterworth  k(1) from scipy.signal.place_poles (A_o(1)^T, C_o^T, Butterworth pattern of radius
               alpha0, gains transposed back; standard sign A_o - k C_o) and the same J indices, for
               alpha0 in {1, 2, 2.5, 2.8, 3, 3.2, 4, 5} (dissertation E7 table).
  e14          the RFID demo plant (dissertation eq. 5.114): continuous coefficients; the
               zero-order-hold discretization at Ts = 0.1 (scipy.signal.cont2discrete, method
               "zoh") as a discrete transfer function; local extrema of |F(j w)| and of
               |G_d(e^{j w Ts})| on a 400001-point log grid over [0.1, 6] rad/s.
"""

import argparse
import json
import os
import warnings

import numpy as np
import scipy
import scipy.linalg as la
import scipy.optimize as opt
import scipy.signal as sig

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "..", "tests", "data", "frf", "frf_observer_reference.json")

N = 11
WEIGHTS = [0.4, 0.4, 0.6, 0.6, 0.8, 0.8, 0.9, 0.9, 1.0, 1.0, 0.6]
V_LIST = [0.5, 0.06, 0.02, 0.0085, 0.005]
ALPHA_LIST = [1.0, 2.0, 2.5, 2.8, 3.0, 3.2, 4.0, 5.0]


def internal_model(w=1.0):
    a = np.zeros((N, N))
    for i in range(1, 6):
        a[2 * i - 2, 2 * i - 1] = i * w
        a[2 * i - 1, 2 * i - 2] = -i * w
    return a


def output_row():
    c = np.zeros((1, N))
    c[0, 0::2] = 1.0
    return c


def mat(m):
    return [[float(x) for x in row] for row in np.atleast_2d(m)]


def vec(v):
    return [float(x) for x in np.ravel(v)]


def channel_system(k, channel):
    """(A, B, C, D) of channel -1 (output estimate), 0 (DC), i = 1..5 ('sin' state of harmonic i)."""
    a = internal_model() - np.outer(k, output_row())
    b = k.reshape(N, 1)
    if channel < 0:
        c = output_row()
    else:
        c = np.zeros((1, N))
        c[0, 10 if channel == 0 else 2 * channel - 2] = 1.0
    return a, b, c, np.zeros((1, 1))


def peak_db(k, channel):
    system = channel_system(k, channel)
    grid = np.logspace(-2, 3, 40001)
    _, h = sig.freqresp(system, grid)
    mag = np.abs(h)
    i = int(np.argmax(mag))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    f = lambda w: -np.abs(sig.freqresp(system, [w])[1][0])
    res = opt.minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10})
    return float(20 * np.log10(max(mag[i], -res.fun)))


def bandwidth(k):
    """First frequency above 5 (x omega) where |F_yhat_y| falls below -3 dB."""
    system = channel_system(k, -1)
    grid = np.logspace(np.log10(5.5), 3, 200001)
    _, h = sig.freqresp(system, grid)
    below = np.nonzero(20 * np.log10(np.abs(h)) < -3.0103)[0]
    i = int(below[0])
    f = lambda w: 20 * np.log10(np.abs(sig.freqresp(system, [w])[1][0])) + 3.0103
    return float(opt.brentq(f, grid[i - 1], grid[i]))


def indices(k):
    return {
        "J_yhat_db": peak_db(k, -1),
        "J_dc_db": peak_db(k, 0),
        "J_harmonic_db": [peak_db(k, i) for i in range(1, 6)],
        "bandwidth": bandwidth(k),
    }


def butterworth_poles(alpha0):
    poles = []
    for m in range(1, 6):
        z = alpha0 * np.exp(1j * (2 * m + 10) * np.pi / 22)
        poles += [z, np.conj(z)]
    poles.append(-alpha0)
    return np.array(poles)


def care_cases():
    rng = np.random.default_rng(20240601)
    cases = []
    a, c = internal_model(), output_row()
    for v in (0.5, 0.02):
        q, r = np.diag(WEIGHTS), np.array([[v]])
        x = la.solve_continuous_are(a.T, c.T, q, r)
        cases.append({"name": f"harmonic_observer_v{v}", "A": mat(a.T), "B": mat(c.T), "Q": mat(q), "R": mat(r), "X": mat(x)})
    for n, m, name in ((4, 1, "random_unstable_4x1"), (6, 2, "random_6x2"), (8, 3, "random_8x3")):
        a_r = rng.standard_normal((n, n)) + 0.5 * np.eye(n)  # typically a few unstable eigenvalues
        b_r = rng.standard_normal((n, m))
        g = rng.standard_normal((n, n))
        q_r = g @ g.T / n + 1e-3 * np.eye(n)
        h = rng.standard_normal((m, m))
        r_r = h @ h.T + m * np.eye(m)
        x = la.solve_continuous_are(a_r, b_r, q_r, r_r)
        cases.append({"name": name, "A": mat(a_r), "B": mat(b_r), "Q": mat(q_r), "R": mat(r_r), "X": mat(x),
                      "open_loop_unstable": bool(np.max(np.linalg.eigvals(a_r).real) > 0)})
    return cases


def e14():
    num = np.polymul([1, 0.06339, 0.06057], [1, 0.1129, 2.064])
    den = np.polymul(np.polymul([1, 0.04544], [1, 0.04541, 0.9985]), [1, 0.9854, 9.12])
    ts = 0.1
    numd, dend, _ = sig.cont2discrete((num, den), ts, method="zoh")
    numd = np.ravel(numd)
    grid = np.logspace(np.log10(0.1), np.log10(6.0), 400001)
    _, hc = sig.freqs(num, den, grid)
    _, hd = sig.freqz(numd, dend, grid * ts)
    out = {"num": vec(num), "den": vec(den), "ts": ts, "numd": vec(numd), "dend": vec(dend)}
    for label, h in (("continuous", hc), ("discrete", hd)):
        mag = np.abs(h)
        out[label + "_maxima"] = [float(grid[i]) for i in sig.argrelextrema(mag, np.greater)[0]]
        out[label + "_minima"] = [float(grid[i]) for i in sig.argrelextrema(mag, np.less)[0]]
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default=DEFAULT_OUT)
    args = parser.parse_args()
    # scipy's transfer-function normalisation (used inside freqresp and cont2discrete) warns about
    # exactly-zero leading numerator coefficients of strictly proper systems; they are harmless.
    warnings.simplefilter("ignore", sig.BadCoefficients)

    a, c = internal_model(), output_row()
    kalman = []
    for v in V_LIST:
        y = la.solve_continuous_are(a.T, c.T, np.diag(WEIGHTS), np.array([[v]]))
        k = (y @ c.T / v).ravel()
        kalman.append({"v": v, "k1": vec(k), **indices(k)})
    v_sweep = []
    for v in np.exp(np.linspace(np.log(0.005), np.log(0.5), 13)):
        y = la.solve_continuous_are(a.T, c.T, np.diag(WEIGHTS), np.array([[v]]))
        v_sweep.append({"v": float(v), "J_yhat_db": peak_db((y @ c.T / v).ravel(), -1)})
    butterworth = []
    for alpha0 in ALPHA_LIST:
        k = sig.place_poles(a.T, c.T, butterworth_poles(alpha0)).gain_matrix.ravel()
        butterworth.append({"alpha0": alpha0, "k1": vec(k), "markov": float(c @ k), **indices(k)})

    data = {
        "generator": {"script": "tools/reference/frf_observer_reference.py", "numpy": np.__version__,
                      "scipy": scipy.__version__},
        "weights": WEIGHTS,
        "care": care_cases(),
        "kalman": kalman,
        "kalman_v_sweep": v_sweep,
        "butterworth": butterworth,
        "e14": e14(),
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    with open(args.output, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
