#!/usr/bin/env python3
"""Reference values for the excitation design (tests/frf/test_excitation_design.cpp).

Independent of the C++ code: numpy's FFT synthesizes the multisine period from Schroeder's
phases (M. R. Schroeder, IEEE Trans. Inf. Theory 16(1), 1970, eq. 11, phi_k = -pi k(k-1)/K for
k = 1 ... K equal lines) and the crest factor max|u|/rms(u) is measured on it; the chirp's number
of whole cycles comes from Farina's exponential sweep phase at the end of the period.

Run: /usr/bin/python3 tools/reference/excitation_reference.py  (prints the values the test uses)
"""
import numpy as np


def schroeder_crest_factor(n, lines):
    k = len(lines)
    spectrum = np.zeros(n // 2 + 1, dtype=complex)
    j = np.arange(1, k + 1)
    spectrum[lines] = np.exp(-1j * np.pi * j * (j - 1) / k)
    u = np.fft.irfft(spectrum, n)
    return np.max(np.abs(u)) / np.sqrt(np.mean(u ** 2))


def chirp_cycles(f_begin, f_end, sweep_s):
    rate = sweep_s / np.log(f_end / f_begin)
    return rate * (f_end - f_begin)


if __name__ == "__main__":
    # 1 ... 499 Hz at 1 ms over 10 s: period 1000 samples (df 1 Hz), lines 1 ... 499.
    print("schroeder 1000 samples, lines 1..499: %.15g" % schroeder_crest_factor(1000, np.arange(1, 500)))
    # 2 ... 200 Hz at 0.5 ms, period 2000 samples (df 1 Hz): lines 2 ... 200.
    print("schroeder 2000 samples, lines 2..200: %.15g" % schroeder_crest_factor(2000, np.arange(2, 201)))
    print("chirp 5..400 Hz over 4 s: %.15g cycles" % chirp_cycles(5.0, 400.0, 4.0))
