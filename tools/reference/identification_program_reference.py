#!/usr/bin/python3
"""Reference values for tests/motion/test_identification_program.cpp.

An independent implementation of the rule documented in
include/servotwin/motion/identification_program.hpp:

* MT19937-64 written out from its published definition (Matsumoto & Nishimura 2000, as specified
  for std::mt19937_64 in [rand.predef]); checked against the value the C++ standard mandates for
  the 10000th output of a default-seeded engine (9981545732273789042).
* u = (x >> 11) * 2^-53, s = 2u - 1, offset = round_half_away(K * s) with K = range * 10^decimals.
* redraw when equal to the axis's previous target (and, for the last drawn value, the next one);
  shapes Standard / Low / High with High's mirrored second half.

Writes tests/data/motion/identification_reference.json with, per case, the expected offsets of
every move (in output steps from the centre, selected axes in X, Y, Z order), and for the
uniformity test the chi-square statistic of 10000 targets in 20 bins and the KS statistic, with
critical values from scipy.

Run: /usr/bin/python3 tools/reference/identification_program_reference.py
"""
import json
import math
import os
import re

from scipy import stats

MASK64 = (1 << 64) - 1


class MT19937_64:
    n, m, r = 312, 156, 31
    a = 0xB5026F5AA96619E9
    u, d = 29, 0x5555555555555555
    s, b = 17, 0x71D67FFFEDA60000
    t, c = 37, 0xFFF7EEE000000000
    l = 43
    f = 6364136223846793005
    lower = (1 << 31) - 1
    upper = (~lower) & MASK64

    def __init__(self, seed):
        self.mt = [0] * self.n
        self.mt[0] = seed & MASK64
        for i in range(1, self.n):
            prev = self.mt[i - 1]
            self.mt[i] = (self.f * (prev ^ (prev >> 62)) + i) & MASK64
        self.index = self.n

    def _twist(self):
        for i in range(self.n):
            x = (self.mt[i] & self.upper) | (self.mt[(i + 1) % self.n] & self.lower)
            xa = x >> 1
            if x & 1:
                xa ^= self.a
            self.mt[i] = self.mt[(i + self.m) % self.n] ^ xa
        self.index = 0

    def __call__(self):
        if self.index >= self.n:
            self._twist()
        y = self.mt[self.index]
        self.index += 1
        y ^= (y >> self.u) & self.d
        y ^= (y << self.s) & self.b
        y ^= (y << self.t) & self.c
        y ^= y >> self.l
        return y & MASK64


def check_engine():
    e = MT19937_64(5489)
    for _ in range(9999):
        e()
    assert e() == 9981545732273789042, "MT19937-64 implementation does not match the C++ standard"


def round_half_away(v):
    """std::llround: nearest integer, halves away from zero (exact for |v| < 2^52)."""
    a = abs(v)
    f = math.floor(a)
    r = f + (1 if a - f >= 0.5 else 0)
    return int(r) if v >= 0 else -int(r)


class Draw:
    def __init__(self, seed, K):
        self.e = MT19937_64(seed)
        self.K = float(K)

    def next(self, previous, other=None):
        while True:
            x = self.e()
            u = (x >> 11) / 2.0**53  # exact
            s = 2.0 * u - 1.0  # exact
            k = round_half_away(self.K * s)  # one IEEE multiplication, as in C++
            if k != previous and (other is None or k != other):
                return k


def offsets(shape, moves, seed, K, naxes):
    """Offsets of every move after positioning (list of tuples, one entry per selected axis)."""
    draw = Draw(seed, K)
    out = []
    prev = [0] * naxes
    if shape in ("low", "high"):
        out += [tuple([-K] * naxes), tuple([K] * naxes)]
        prev = [K] * naxes
    mirrored = moves // 2 if shape == "high" else 0
    drawn = moves - mirrored
    rnd = []
    for i in range(drawn):
        row = []
        for a in range(naxes):
            other = None
            if i == drawn - 1:
                if mirrored == 0:
                    other = -K if shape == "high" else 0
                elif drawn == mirrored:
                    other = 0
                else:
                    other = -rnd[mirrored - 1][a]
            v = draw.next(prev[a], other)
            row.append(v)
            prev[a] = v
        rnd.append(tuple(row))
    out += rnd
    out += [tuple(-v for v in rnd[mirrored - 1 - j]) for j in range(mirrored)]
    if shape == "high":
        out += [tuple([-K] * naxes), tuple([K] * naxes)]
    out.append(tuple([0] * naxes))
    return out


CASES = [
    # name, set, axes, moves, seed, range_mm, decimals
    ("standard_x_seed7", "standard", "X", 12, 7, 10.0, 3),
    ("high_x_odd_seed7", "high", "X", 9, 7, 10.0, 3),
    ("high_xy_even_seed42", "high", "XY", 8, 42, 10.0, 3),
    ("high_x_one_move", "high", "X", 1, 5, 10.0, 3),
    ("low_x_seed3", "low", "X", 10, 3, 0.03, 3),
    ("standard_xyz_tiny_range", "standard", "XYZ", 6, (1 << 63) + 5, 0.001, 3),
    ("standard_y_decimals4", "standard", "Y", 7, 11, 2.5, 4),
]


def uniformity(seed, n, range_mm, bins):
    K = int(round(range_mm * 1000))
    offs = [o[0] for o in offsets("standard", n, seed, K, 1)][:-1]  # the random moves only
    x = [o / 1000.0 for o in offs]
    counts = [0] * bins
    for v in x:
        b = min(int((v + range_mm) / (2 * range_mm) * bins), bins - 1)
        counts[b] += 1
    expected = n / bins
    chi2 = sum((c - expected) ** 2 / expected for c in counts)
    ks = stats.kstest(x, stats.uniform(loc=-range_mm, scale=2 * range_mm).cdf)
    return {
        "seed": seed,
        "moves": n,
        "range_mm": range_mm,
        "bins": bins,
        "counts": counts,
        "chi2": chi2,
        "chi2_critical_0999": float(stats.chi2.ppf(0.999, bins - 1)),
        "ks_statistic": float(ks.statistic),
        "ks_critical_0999": float(stats.kstwo.ppf(0.999, n)),
        "first_offsets": offs[:5],
    }


def main():
    check_engine()
    cases = []
    for name, shape, axes, moves, seed, range_mm, decimals in CASES:
        K = int(round(range_mm * 10**decimals))
        cases.append({
            "name": name,
            "set": shape,
            "axes": axes,
            "moves": moves,
            "seed": str(seed),  # JSON numbers cannot hold every uint64 exactly
            "range_mm": range_mm,
            "decimals": decimals,
            "offsets": [list(o) for o in offsets(shape, moves, seed, K, len(axes))],
        })
    doc = {
        "source": "tools/reference/identification_program_reference.py",
        "mt19937_64_check": "10000th output of seed 5489 = 9981545732273789042",
        "cases": cases,
        "uniformity": uniformity(seed=2007, n=10000, range_mm=10.0, bins=20),
    }
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "..", "tests", "data", "motion", "identification_reference.json")
    text = json.dumps(doc, indent=1)
    # One line per innermost list of numbers keeps the file readable.
    text = re.sub(r"\[\s+(-?[\d.e+-]+(?:,\s+-?[\d.e+-]+)*)\s+\]", lambda m: "[" + re.sub(r"\s+", " ", m.group(1)) + "]", text)
    with open(path, "w") as fh:
        fh.write(text + "\n")
    print("wrote", os.path.normpath(path))


if __name__ == "__main__":
    main()
