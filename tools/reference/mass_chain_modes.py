#!/usr/bin/env python3
"""Modes of a damped mass chain, for tests/fit/test_friction_fit.cpp (three-mass chain).

Independent of servotwin's chain walk: the poles are the roots of det(M s^2 + B s + K) (the
free chain; the rigid mode's roots at 0 dropped), the motor side's antiresonances those of the
minor with the motor's row and column struck out (the motor held). Polynomial determinants by
cofactor expansion, roots by Durand-Kerner iteration; standard library only, 1e-12.

Usage: python3 tools/reference/mass_chain_modes.py
"""
import math


def pmul(a, b):
    r = [0.0] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            r[i + j] += x * y
    return r


def padd(a, b, sign=1.0):
    n = max(len(a), len(b))
    a = [0.0] * (n - len(a)) + a
    b = [0.0] * (n - len(b)) + b
    return [x + sign * y for x, y in zip(a, b)]


def det(m):
    if len(m) == 1:
        return m[0][0]
    r = [0.0]
    for j in range(len(m)):
        minor = [row[:j] + row[j + 1:] for row in m[1:]]
        r = padd(r, pmul(m[0][j], det(minor)), 1.0 if j % 2 == 0 else -1.0)
    return r


def roots(p):
    while abs(p[0]) == 0.0:
        p = p[1:]
    p = [x / p[0] for x in p]
    n = len(p) - 1
    z = [(0.4 + 0.9j) ** k * 1000.0 for k in range(n)]
    for _ in range(5000):
        nz = []
        for i in range(n):
            v = 0.0
            for c in p:
                v = v * z[i] + c
            d = 1.0
            for j in range(n):
                if j != i:
                    d *= z[i] - z[j]
            nz.append(z[i] - v / d)
        z = nz
    return z


def chain_matrix(inertia, stiffness, damping):
    """Entries of M s^2 + B s + K as polynomials in s (highest power first)."""
    n = len(inertia)
    m = [[[0.0] for _ in range(n)] for _ in range(n)]
    for i in range(n):
        m[i][i] = [inertia[i], 0.0, 0.0]
    for i in range(n - 1):
        e = [0.0, damping[i], stiffness[i]]
        for a, b, s in ((i, i, 1.0), (i + 1, i + 1, 1.0), (i, i + 1, -1.0), (i + 1, i, -1.0)):
            m[a][b] = padd(m[a][b], e, s)
    return m


def pairs(poly):
    return sorted((abs(r) / (2 * math.pi), -r.real / abs(r)) for r in roots(poly) if abs(r) > 1e-6 and r.imag > 1e-6 * abs(r))


def main():
    inertia, stiffness, damping = [2e-3, 1e-3, 6e-3], [2500.0, 400.0], [0.02, 0.01]
    m = chain_matrix(inertia, stiffness, damping)
    for hz, zeta in pairs(det(m)):
        print(f"resonance     {hz:.9f} Hz  zeta {zeta:.9f}")
    for hz, zeta in pairs(det([row[1:] for row in m[1:]])):
        print(f"antiresonance {hz:.9f} Hz  zeta {zeta:.9f}")


if __name__ == "__main__":
    main()
