#!/usr/bin/env python3
"""Independent reference for servotwin's shaper-selection measure (shaping/selection.hpp).

Implements, from its definition (Klipper's calibrate_shaper as documented in selection.hpp; no code
copied, no servotwin code used), the "remaining vibrations" of a shaper on a Klipper PSD file:

  1. raw PSD normalized: psd / (f + 0.1), times exp(1 - (10 / (f + 0.1))**2) below 10 Hz
     (files with fitted-shaper columns are already normalized and used as they are);
  2. the summed column psd_xyz, bins f <= 200 Hz;
  3. threshold = max(psd) / 20;
  4. R(z) = sum(max(psd * V(f, z) - threshold, 0)) / sum(max(psd - threshold, 0)),
     V the classic residual vibration exp(-z w t_n) |sum A_i exp(z w t_i) exp(j w_d t_i)| / sum A_i;
  5. remaining = max over z in (0.075, 0.1, 0.15).

Shapers: ZV, ZVD and MZV from their closed forms (Singer-Seering; MZV = three impulses 3/8 of a
damped period apart, a = (1 - 1/sqrt2)[1, sqrt2, 1] times K^i), designed for damping 0.1 at the
(type, frequency) Klipper chose per family (README of each data folder), plus a two-mode shaper
(ZV x ZV convolution) to check the convolution path. Writes
tests/data/shaping/klipper_selection.json.
"""
import json
import math
import os

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.path.join(ROOT, "data")
OUT = os.path.join(ROOT, "tests", "data", "shaping", "klipper_selection.json")


def load(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [line.strip().split(",") for line in f if line.strip() and not line.startswith("#")]
    idx = {name: header.index(name) for name in ("freq", "psd_xyz")}
    freq = np.array([float(r[idx["freq"]]) for r in rows])
    psd = np.array([float(r[idx["psd_xyz"]]) for r in rows])
    normalized = any("(" in h for h in header) or "shapers:" in header
    return freq, psd, normalized


def prepare(freq, psd, normalized):
    keep = freq <= 200.0
    freq, psd = freq[keep], psd[keep].copy()
    if not normalized:
        psd = psd / (freq + 0.1)
        low = freq < 10.0
        psd[low] *= np.exp(1.0 - (10.0 / (freq[low] + 0.1)) ** 2)
    return freq, psd


def zv(f, z):
    k = math.exp(-z * math.pi / math.sqrt(1 - z * z))
    td = 1.0 / (f * math.sqrt(1 - z * z))
    a = np.array([1.0, k])
    return a / a.sum(), np.array([0.0, 0.5 * td])


def zvd(f, z):
    k = math.exp(-z * math.pi / math.sqrt(1 - z * z))
    td = 1.0 / (f * math.sqrt(1 - z * z))
    a = np.array([1.0, 2 * k, k * k])
    return a / a.sum(), np.array([0.0, 0.5 * td, td])


def mzv(f, z):
    k = math.exp(-0.75 * z * math.pi / math.sqrt(1 - z * z))
    td = 1.0 / (f * math.sqrt(1 - z * z))
    base = (1 - 1 / math.sqrt(2)) * np.array([1.0, math.sqrt(2), 1.0])
    a = base * np.array([1.0, k, k * k])
    return a / a.sum(), np.array([0.0, 0.375 * td, 0.75 * td])


def convolve(s1, s2):
    a = np.outer(s1[0], s2[0]).ravel()
    t = np.add.outer(s1[1], s2[1]).ravel()
    order = np.argsort(t, kind="stable")
    return a[order], t[order]


def vibration(shaper, freqs, z):
    a, t = shaper
    w = 2 * math.pi * freqs[:, None]
    wd = w * math.sqrt(1 - z * z)
    terms = a[None, :] * np.exp(z * w * t[None, :]) * np.exp(1j * wd * t[None, :])
    return np.abs(terms.sum(axis=1)) * np.exp(-z * w[:, 0] * t[-1]) / a.sum()


def remaining(shaper, freq, psd):
    thr = psd.max() / 20.0
    allv = np.maximum(psd - thr, 0).sum()
    return max(np.maximum(psd * vibration(shaper, freq, z) - thr, 0).sum() / allv for z in (0.075, 0.1, 0.15))


# (file, [(family, freq)]) from the READMEs: current Klipper's zv and mzv choices per file.
CASES = [
    ("klipper-ender5s1-psd/resonances_x_20230321_171058.csv", [("zv", 21.0), ("mzv", 27.6), ("zvd", 40.0)]),
    ("klipper-ender5s1-psd/resonances_y_20230321_171849.csv", [("zv", 22.4), ("mzv", 31.6), ("zvd", 45.0)]),
    ("klipper-ender5s1-psd/calibration_data_x_20230321_165958.csv", [("zv", 21.0), ("mzv", 25.0), ("zvd", 35.0)]),
    ("klipper-ender5s1-psd/calibration_data_y_20230321_165958.csv", [("zv", 51.0), ("mzv", 31.0), ("zvd", 40.0)]),
    ("klipper-voron24-psd/resonances_x_20221231_212825.csv", [("zv", 61.2), ("mzv", 63.4), ("zvd", 70.0)]),
    ("klipper-voron24-psd/resonances_y_20221231_213042.csv", [("zv", 43.0), ("mzv", 44.0), ("zvd", 50.0)]),
]
DESIGNS = {"zv": zv, "zvd": zvd, "mzv": mzv}


def main():
    out = {"generator": "tools/reference/klipper_selection_reference.py", "design_zeta": 0.1, "cases": []}
    for rel, shapers in CASES:
        freq, psd, normalized = load(os.path.join(DATA, rel))
        f, p = prepare(freq, psd, normalized)
        entries = []
        for family, fs in shapers:
            s = DESIGNS[family](fs, 0.1)
            entries.append({"family": family, "freq_hz": fs, "times_s": s[1].tolist(), "amplitudes": s[0].tolist(),
                            "remaining_vibrations": remaining(s, f, p)})
        two = convolve(zv(shapers[0][1], 0.1), zv(2.0 * shapers[0][1], 0.1))
        entries.append({"family": "zv*zv", "freq_hz": shapers[0][1], "times_s": two[1].tolist(),
                        "amplitudes": two[0].tolist(), "remaining_vibrations": remaining(two, f, p)})
        out["cases"].append({"file": rel, "normalized": bool(normalized), "bins": int(len(f)),
                             "psd_max": float(p.max()), "psd_max_freq_hz": float(f[p.argmax()]),
                             "shapers": entries})
    with open(OUT, "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")
    for c in out["cases"]:
        print(c["file"], [(e["family"], e["freq_hz"], round(100 * e["remaining_vibrations"], 2)) for e in c["shapers"]])


if __name__ == "__main__":
    main()
