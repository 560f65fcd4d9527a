#!/usr/bin/env python3
"""Reference values for the servotwin `core` module tests (tests/core/*).

How to run (from the repository root; needs python3 with numpy and scipy, written against
numpy 1.24 / scipy 1.10 as shipped by Debian 12 -- `apt-get install python3-scipy`; use the
system interpreter /usr/bin/python3 if another python3 without scipy comes first on PATH):

    /usr/bin/python3 tools/reference/core_reference.py          # writes tests/data/core/core_reference.json
    /usr/bin/python3 tools/reference/core_reference.py -o FILE  # writes somewhere else

It takes about a second (the 60-digit parts are pure Python).

The script is deterministic (fixed inputs, seeded generator) and the JSON it writes is committed
beside it; re-running it must reproduce the committed file up to the library versions recorded in
the file's "generator" block. Floats are written with Python's shortest round-trip repr, so the C++
tests read back exactly the doubles computed here.

Contents and where each expected value comes from:
  polynomial_roots   reference roots: exact by construction where the polynomial is built from known
                     roots with exactly representable coefficients, otherwise the numpy.roots result
                     refined by Newton's method in 60-digit decimal arithmetic on the exact binary
                     coefficients (so the reference is the true root set of the double-precision
                     polynomial); numpy.roots output is stored too, to compare accuracy with.
  frequency_response scipy.signal.freqs on the stored grid (rad/s).
  tf2ss              scipy.signal.tf2ss.
  zoh                scipy.signal.cont2discrete(..., method="zoh"), and "Ad_exact"/"Bd_exact": the
                     same matrix exponential in 60-digit decimal arithmetic (Taylor series with
                     scaling and squaring), to judge both double-precision results against.
  lsim               scipy.signal.lsim(..., interp=False) (zero-order-held input), and "y_exact":
                     the same recursion with the 60-digit discretization in 60-digit arithmetic.
  dlsim              scipy.signal.dlsim.
  step               scipy.signal.dstep of cont2discrete(tf2ss(tf), ts, "zoh").
"""

import argparse
import decimal
import json
import os
import sys
import warnings

import numpy as np
import scipy
import scipy.signal as sig

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "..", "..", "tests", "data", "core", "core_reference.json")

# Thesis (Wong 2007) closed-loop parameters, Tables 3.3 (P-PI, x axis) and 3.4 (PID, x axis).
PPI = dict(a1=372.76, a2=62009.83, a3=1527104.87, b0=0.0, b1=0.0, b2=11106.33)
PID = dict(a1=192.65, a2=44356.23, a3=316830.21, b0=0.0, b1=190.10, b2=44356.23)

# Two-mass plant (motor inertia J1, load inertia J2, shaft stiffness k, damping c), SI units.
J1, J2, K_SHAFT, C_SHAFT = 1e-3, 2e-3, 500.0, 0.05


def tracking_tf(p):
    """x / x_r = (b0 s^3 + b1 s^2 + b2 s + a3) / (s^3 + a1 s^2 + a2 s + a3) (thesis Eq. 3.3).

    Exact leading zeros of the numerator are dropped (scipy warns about them; servotwin's
    Polynomial drops them too)."""
    num = list(np.trim_zeros([p["b0"], p["b1"], p["b2"], p["a3"]], "f"))
    return num, [1.0, p["a1"], p["a2"], p["a3"]]


def two_mass_ss():
    """States [theta1, omega1, theta2, omega2], input motor torque, outputs [omega1, theta2]."""
    a = np.array([
        [0.0, 1.0, 0.0, 0.0],
        [-K_SHAFT / J1, -C_SHAFT / J1, K_SHAFT / J1, C_SHAFT / J1],
        [0.0, 0.0, 0.0, 1.0],
        [K_SHAFT / J2, C_SHAFT / J2, -K_SHAFT / J2, -C_SHAFT / J2],
    ])
    b = np.array([[0.0], [1.0 / J1], [0.0], [0.0]])
    c = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    d = np.zeros((2, 1))
    return a, b, c, d


def two_mass_velocity_tf():
    """Motor torque -> motor velocity: (J2 s^2 + c s + k) / (s (J1 J2 s^2 + c (J1+J2) s + k (J1+J2)))."""
    num = [J2, C_SHAFT, K_SHAFT]
    den = np.polymul([1.0, 0.0], [J1 * J2, C_SHAFT * (J1 + J2), K_SHAFT * (J1 + J2)])
    return num, list(den)


# ---- high-precision polynomial roots ---------------------------------------------------------

decimal.getcontext().prec = 60
D = decimal.Decimal


class DComplex:
    """Minimal complex arithmetic on Decimals (enough for Horner and Newton)."""

    def __init__(self, re, im=D(0)):
        self.re, self.im = D(re), D(im)

    def __add__(self, o):
        return DComplex(self.re + o.re, self.im + o.im)

    def __sub__(self, o):
        return DComplex(self.re - o.re, self.im - o.im)

    def __mul__(self, o):
        return DComplex(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)

    def __truediv__(self, o):
        den = o.re * o.re + o.im * o.im
        return DComplex((self.re * o.re + self.im * o.im) / den, (self.im * o.re - self.re * o.im) / den)

    def abs2(self):
        return self.re * self.re + self.im * self.im


def newton_refine(coefficients, root):
    """Newton's method in 60-digit arithmetic on the exact binary values of the coefficients."""
    c = [D(float(v)) for v in coefficients]  # Decimal(float) is exact
    z = DComplex(D(float(root.real)), D(float(root.imag)))
    for _ in range(200):
        p = DComplex(0)
        dp = DComplex(0)
        for ci in c:
            dp = dp * z + p
            p = p * z + DComplex(ci)
        if p.abs2() == 0:
            break
        step = p / dp
        z = z - step
        if step.abs2() <= (z.abs2() + D(1e-300)) * D(10) ** -100:
            break
    return complex(float(z.re), float(z.im))


def expm_decimal(m):
    """exp(m) in 60-digit arithmetic (m a list of lists of floats, taken exactly): scaling so the
    norm is below 2^-8, a 40-term Taylor series (truncation < 1e-100), then repeated squaring."""
    n = len(m)
    a = [[D(float(v)) for v in row] for row in m]
    norm = max(sum(abs(v) for v in row) for row in a) if n else D(0)
    squarings = 0
    while norm > D(2) ** -8:
        norm /= 2
        squarings += 1
    scale = D(2) ** squarings
    a = [[v / scale for v in row] for row in a]

    def matmul(x, y):
        return [[sum(x[i][k] * y[k][j] for k in range(n)) for j in range(n)] for i in range(n)]

    result = [[D(1) if i == j else D(0) for j in range(n)] for i in range(n)]
    term = [row[:] for row in result]
    for k in range(1, 41):
        term = [[v / k for v in row] for row in matmul(term, a)]
        result = [[result[i][j] + term[i][j] for j in range(n)] for i in range(n)]
    for _ in range(squarings):
        result = matmul(result, result)
    return result


def zoh_decimal(a, b, ts):
    """Exact (60-digit) zero-order-hold matrices of the double-precision product [[A B][0 0]] * ts,
    i.e. of exactly the matrix that scipy and servotwin exponentiate."""
    n, m = a.shape[0], b.shape[1]
    em = np.zeros((n + m, n + m))
    em[:n, :n] = a
    em[:n, n:] = b
    e = expm_decimal((ts * em).tolist())
    return [row[:n] for row in e[:n]], [row[n:] for row in e[:n]]


def simulate_decimal(ad, bd, c, d, u, x0):
    """y[k] = C x[k] + D u[k], x[k+1] = Ad x[k] + Bd u[k] in 60-digit arithmetic."""
    n = len(ad)
    cd = [[D(float(v)) for v in row] for row in np.atleast_2d(c)]
    dd = [[D(float(v)) for v in row] for row in np.atleast_2d(d)]
    x = [D(float(v)) for v in x0]
    out = []
    for uk in np.atleast_2d(u):
        uk = [D(float(v)) for v in np.atleast_1d(uk)]
        y = [sum(cd[r][i] * x[i] for i in range(n)) + sum(dd[r][j] * uk[j] for j in range(len(uk)))
             for r in range(len(cd))]
        out.append([float(v) for v in y])
        x = [sum(ad[i][j] * x[j] for j in range(n)) + sum(bd[i][j] * uk[j] for j in range(len(uk)))
             for i in range(n)]
    return out


def to_floats(rows):
    return [[float(v) for v in row] for row in rows]


def roots_case(name, coefficients, exact_roots=None, note=""):
    coefficients = [float(v) for v in coefficients]
    numpy_roots = np.roots(coefficients)
    if exact_roots is not None:
        reference = np.array(exact_roots, dtype=complex)
        source = "exact (built from these roots; coefficients exactly representable)"
    else:
        reference = np.array([newton_refine(coefficients, r) for r in numpy_roots])
        source = "numpy.roots refined by 60-digit Newton on the exact double coefficients"
        # Newton from a good start stays on its own root only when roots are simple and separated.
        for i in range(len(reference)):
            for j in range(i + 1, len(reference)):
                gap = abs(reference[i] - reference[j])
                assert gap > 1e-6 * max(abs(reference[i]), 1e-300), f"{name}: refined roots coincide"
    return {
        "name": name,
        "note": note,
        "coefficients": coefficients,
        "reference_roots": [[r.real, r.imag] for r in reference],
        "reference_source": source,
        "numpy_roots": [[r.real, r.imag] for r in numpy_roots],
    }


def polynomial_cases():
    cases = []
    cases.append(roots_case("triple_root_times_simple", np.poly([-1, -1, -1, -2]), [-1, -1, -1, -2],
                            "(s+1)^3 (s+2): a triple root, ill-conditioned"))
    cases.append(roots_case("quadruple_root", np.poly([-2, -2, -2, -2]), [-2, -2, -2, -2], "(s+2)^4"))
    num, den = tracking_tf(PPI)
    cases.append(roots_case("thesis_ppi_denominator", den, None,
                            "s^3 + 372.76 s^2 + 62009.83 s + 1527104.87 (Table 3.3, x axis): wide scale"))
    num, den = tracking_tf(PID)
    cases.append(roots_case("thesis_pid_denominator", den, None, "Table 3.4 x axis poles"))
    cases.append(roots_case("thesis_pid_numerator", num, None, "Table 3.4 x axis zeros (b0 = 0)"))
    cases.append(roots_case("complex_pairs", np.polymul(np.polymul([1, 2, 5], [1, 0.2, 100]), [1, 3]), None,
                            "(s^2+2s+5)(s^2+0.2s+100)(s+3); 0.2 is not exact in binary, so refined roots"))
    cases.append(roots_case("exact_complex_pairs", np.polymul([1, 2, 5], [1, 4, 13]),
                            [complex(-1, 2), complex(-1, -2), complex(-2, 3), complex(-2, -3)],
                            "(s^2+2s+5)(s^2+4s+13)"))
    cases.append(roots_case("zero_roots", np.polymul([1, 0, 0], np.polymul([1, 4], [1, 1, 1])),
                            [0, 0, -4, complex(-0.5, np.sqrt(3) / 2), complex(-0.5, -np.sqrt(3) / 2)],
                            "s^2 (s+4)(s^2+s+1): trailing zeros give exact zero roots"))
    cases.append(roots_case("double_complex_pair", np.polymul([1, 2, 5], [1, 2, 5]),
                            [complex(-1, 2), complex(-1, 2), complex(-1, -2), complex(-1, -2)], "(s^2+2s+5)^2"))
    cases.append(roots_case("wilkinson_10", np.poly(np.arange(1, 11)), list(range(1, 11)),
                            "prod_{k=1..10} (s-k): integer coefficients, exact; ill-conditioned"))
    num, den = two_mass_velocity_tf()
    cases.append(roots_case("two_mass_denominator", den, None, "s (J1 J2 s^2 + c(J1+J2) s + k(J1+J2))"))
    cases.append(roots_case("decades_apart", np.poly([-0.01, -1, -100, -1e4]), None,
                            "(s+0.01)(s+1)(s+100)(s+1e4): roots over six decades"))
    cases.append(roots_case("close_distinct", np.polymul([1, 1], [1, 1.001]), None,
                            "(s+1)(s+1.001): close but distinct roots must stay distinct"))
    cases.append(roots_case("quadratic_disparate", [1, 1e8, 1], None, "s^2 + 1e8 s + 1: naive formula cancels"))
    cases.append(roots_case("unstable", np.polymul([1, -1], [1, -2, 10]), [1, complex(1, 3), complex(1, -3)],
                            "(s-1)(s^2-2s+10): right half plane"))
    b, a = sig.butter(8, 100.0, analog=True)
    butter_poles = [100.0 * np.exp(1j * np.pi * (2 * k + 8 + 1) / 16) for k in range(8)]
    case = roots_case("butterworth_8", a, None, "8th-order analog Butterworth, cutoff 100 rad/s")
    case["closed_form_roots"] = [[r.real, r.imag] for r in butter_poles]
    cases.append(case)
    return cases


# ---- transfer functions ----------------------------------------------------------------------

def tf_cases():
    cases = []
    num, den = tracking_tf(PID)
    cases.append(("thesis_pid_tracking", num, den))
    num, den = tracking_tf(PPI)
    cases.append(("thesis_ppi_tracking", num, den))
    num, den = two_mass_velocity_tf()
    cases.append(("two_mass_velocity", num, den))
    b, a = sig.butter(8, 100.0, analog=True)
    cases.append(("butterworth_8", list(b), list(a)))
    cases.append(("lead_biproper", [2.0, 20.0], [1.0, 100.0]))
    cases.append(("integrator", [1.0], [1.0, 0.0]))
    cases.append(("non_monic", [2.0, 3.0], [4.0, 5.0, 6.0]))
    return cases


def frequency_response_cases():
    out = []
    for name, num, den in tf_cases():
        omega = np.logspace(-1, 5, 121)
        _, h = sig.freqs(num, den, worN=omega)
        out.append({"name": name, "num": [float(v) for v in num], "den": [float(v) for v in den],
                    "omega": list(omega), "re": list(h.real), "im": list(h.imag)})
    return out


def matrix(m):
    return [list(map(float, row)) for row in np.atleast_2d(m)]


def tf2ss_cases():
    out = []
    extra = [("static_gain", [3.0], [2.0]), ("zero_numerator", [0.0], [1.0, 2.0, 3.0])]
    for name, num, den in tf_cases() + extra:
        if name == "butterworth_8":
            continue  # covered by the others; keeps the fixture small
        with warnings.catch_warnings():
            # scipy warns that an all-zero numerator is "badly conditioned"; that case is on purpose.
            if name == "zero_numerator":
                warnings.simplefilter("ignore", sig.BadCoefficients)
            a, b, c, d = sig.tf2ss(num, den)
        out.append({"name": name, "num": [float(v) for v in num], "den": [float(v) for v in den],
                    "A": matrix(a), "B": matrix(b), "C": matrix(c), "D": matrix(d)})
    return out


def zoh_cases():
    out = []
    systems = []
    systems.append(("two_mass", *two_mass_ss(), 1e-3))
    num, den = tracking_tf(PID)
    systems.append(("thesis_pid_tracking", *sig.tf2ss(num, den), 1e-3))
    systems.append(("integrator", *sig.tf2ss([1.0], [1.0, 0.0]), 0.01))
    systems.append(("double_integrator", np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]),
                    np.array([[1.0, 0.0]]), np.zeros((1, 1)), 0.5))
    rng = np.random.RandomState(20240607)
    a = rng.randn(3, 3) - 2.0 * np.eye(3)
    systems.append(("random_3x2x2", a, rng.randn(3, 2), rng.randn(2, 3), rng.randn(2, 2), 0.05))
    for name, a, b, c, d, ts in systems:
        ad, bd, cd, dd, _ = sig.cont2discrete((a, b, c, d), ts, method="zoh")
        ad_exact, bd_exact = zoh_decimal(np.asarray(a, float), np.asarray(b, float), ts)
        out.append({"name": name, "ts": ts, "A": matrix(a), "B": matrix(b), "C": matrix(c), "D": matrix(d),
                    "Ad": matrix(ad), "Bd": matrix(bd), "Cd": matrix(cd), "Dd": matrix(dd),
                    "Ad_exact": to_floats(ad_exact), "Bd_exact": to_floats(bd_exact)})
    return out


def lsim_cases():
    out = []
    ts = 1e-3
    # Two-mass plant driven by a torque that switches sign (a crude PRBS) plus a small sine.
    n = 400
    t = np.arange(n) * ts
    rng = np.random.RandomState(7)
    prbs = np.repeat(np.sign(rng.randn(n // 20)), 20) * 0.05
    u = prbs + 0.02 * np.sin(2 * np.pi * 50 * t)
    a, b, c, d = two_mass_ss()
    x0 = np.array([0.0, 0.0, 1e-4, 0.0])
    _, y, _ = sig.lsim((a, b, c, d), u, t, X0=x0, interp=False)
    ad, bd = zoh_decimal(a, b, ts)
    out.append({"name": "two_mass_prbs", "ts": ts, "A": matrix(a), "B": matrix(b), "C": matrix(c), "D": matrix(d),
                "x0": list(x0), "u": [[v] for v in u], "y": matrix(y),
                "y_exact": simulate_decimal(ad, bd, c, d, u[:, None], x0)})
    # Thesis PID closed loop following a smooth 10 mm move (cosine ramp over 0.2 s, then hold).
    n = 500
    t = np.arange(n) * ts
    ramp = np.where(t < 0.2, 5.0 * (1.0 - np.cos(np.pi * t / 0.2)), 10.0)
    num, den = tracking_tf(PID)
    a, b, c, d = sig.tf2ss(num, den)
    _, y, _ = sig.lsim((a, b, c, d), ramp, t, interp=False)
    ad, bd = zoh_decimal(a, b, ts)
    out.append({"name": "thesis_pid_tracking_move", "ts": ts, "A": matrix(a), "B": matrix(b), "C": matrix(c),
                "D": matrix(d), "x0": [0.0] * a.shape[0], "u": [[v] for v in ramp],
                "y": [[v] for v in np.atleast_1d(y)],
                "y_exact": simulate_decimal(ad, bd, c, d, ramp[:, None], [0.0] * a.shape[0])})
    return out


def dlsim_cases():
    out = []
    rng = np.random.RandomState(99)
    a = np.array([[0.9, 0.2, 0.0], [-0.2, 0.9, 0.1], [0.0, 0.0, 0.5]])
    b = rng.randn(3, 2)
    c = rng.randn(2, 3)
    d = rng.randn(2, 2)
    n = 60
    u = rng.randn(n, 2)
    x0 = np.array([1.0, -0.5, 0.25])
    ts = 0.01
    _, y, _ = sig.dlsim((a, b, c, d, ts), u, x0=x0)
    out.append({"name": "mimo_3x2x2", "ts": ts, "A": matrix(a), "B": matrix(b), "C": matrix(c), "D": matrix(d),
                "x0": list(x0), "u": matrix(u), "y": matrix(y)})
    return out


def step_cases():
    out = []
    for name, num, den, ts, n in [
        ("thesis_pid_tracking", *tracking_tf(PID), 1e-3, 300),
        ("thesis_ppi_tracking", *tracking_tf(PPI), 1e-3, 300),
        ("lead_biproper", [2.0, 20.0], [1.0, 100.0], 1e-3, 50),
    ]:
        ad, bd, cd, dd, _ = sig.cont2discrete(sig.tf2ss(num, den), ts, method="zoh")
        _, (y,) = sig.dstep((ad, bd, cd, dd, ts), n=n)
        out.append({"name": name, "num": [float(v) for v in num], "den": [float(v) for v in den], "ts": ts,
                    "y": [float(v) for v in y[:, 0]]})
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-o", "--output", default=DEFAULT_OUT)
    args = parser.parse_args()
    data = {
        "generator": {"script": "tools/reference/core_reference.py", "python": sys.version.split()[0],
                      "numpy": np.__version__, "scipy": scipy.__version__},
        "polynomial_roots": polynomial_cases(),
        "frequency_response": frequency_response_cases(),
        "tf2ss": tf2ss_cases(),
        "zoh": zoh_cases(),
        "lsim": lsim_cases(),
        "dlsim": dlsim_cases(),
        "step": step_cases(),
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    with open(args.output, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    print(f"wrote {os.path.normpath(args.output)}")


if __name__ == "__main__":
    main()
