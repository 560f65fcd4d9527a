#!/usr/bin/env python3
"""Reference values for the drive filters (servotwin::tuning drive_filter tests, issue 25 §5).

Independent of the C++ code:
* the continuous filters are written from their definitions (docs/controller-tuning-study.md,
  include/servotwin/tuning/drive_filter.hpp): notch (s^2 + 2 zz w s + w^2)/(s^2 + 2 zp w s + w^2)
  with zp = width/(2 f), zz = zp 10^(-depth/20); lowpass w/(s + w) or w^2/(s^2 + 2 z w s + w^2);
  biquad (wp/wz)^2 (s^2 + 2 dz wz s + wz^2)/(s^2 + 2 dp wp s + wp^2);
* the discrete biquads come from scipy.signal.bilinear, whose map is s = 2 fs (z - 1)/(z + 1):
  prewarping at w0 is that map with fs = w0 / (2 tan(w0 ts / 2));
* the discrete responses at the prewarp frequency from scipy.signal.freqz;
* the notch's -3 dB band (infinite depth) by brute-force root bracketing of |N(jw)|^2 = 1/2 with
  scipy.optimize.brentq.

Writes tests/data/tuning/drive_filter_reference.json.
"""
import json
import math
import os

import numpy as np
from scipy import optimize, signal

TS = 0.000125  # an 8 kHz drive


def notch(f, width, depth):
    w = 2 * math.pi * f
    zp = width / (2 * f)
    zz = zp * 10 ** (-depth / 20)
    return [1.0, 2 * zz * w, w * w], [1.0, 2 * zp * w, w * w], w


def lowpass(f, zeta=None):
    w = 2 * math.pi * f
    if zeta is None:
        return [w], [1.0, w], w
    return [w * w], [1.0, 2 * zeta * w, w * w], w


def biquad(fz, dz, fp, dp):
    wz, wp = 2 * math.pi * fz, 2 * math.pi * fp
    g = (wp / wz) ** 2
    prewarp = wp if dp < dz else wz
    return [g, g * 2 * dz * wz, g * wz * wz], [1.0, 2 * dp * wp, wp * wp], prewarp


def discrete(num, den, w0, ts):
    fs = w0 / (2 * math.tan(w0 * ts / 2))
    b, a = signal.bilinear(num, den, fs=fs)
    b = list(b / a[0])
    a = list(a / a[0])
    while len(b) < 3:
        b.append(0.0)
    while len(a) < 3:
        a.append(0.0)
    _, h = signal.freqz(b, a, worN=[w0 * ts])
    return {"b": b, "a": a, "response_at_prewarp": [h[0].real, h[0].imag]}


def continuous_response(num, den, w):
    s = 1j * w
    return np.polyval(num, s) / np.polyval(den, s)


def case(name, spec, num, den, w0):
    d = discrete(num, den, w0, TS)
    c = continuous_response(num, den, w0)
    return {"name": name, "spec": spec, "num": list(num), "den": list(den), "prewarp_hz": w0 / (2 * math.pi),
            "continuous_at_prewarp": [c.real, c.imag], **d}


def main():
    cases = []
    n, d, w0 = notch(254.0, 80.0, 26.0)
    cases.append(case("notch", {"type": "notch", "frequency_hz": 254.0, "width_hz": 80.0, "depth_db": 26.0}, n, d, w0))
    n, d, w0 = notch(1500.0, 300.0, 40.0)
    cases.append(case("notch_high", {"type": "notch", "frequency_hz": 1500.0, "width_hz": 300.0, "depth_db": 40.0}, n, d, w0))
    n, d, w0 = lowpass(800.0)
    cases.append(case("lowpass1", {"type": "lowpass", "frequency_hz": 800.0}, n, d, w0))
    n, d, w0 = lowpass(1200.0, 0.6)
    cases.append(case("lowpass2", {"type": "lowpass", "frequency_hz": 1200.0, "damping": 0.6}, n, d, w0))
    n, d, w0 = biquad(300.0, 0.05, 350.0, 0.4)
    cases.append(case("biquad", {"type": "biquad", "frequency_hz": 300.0, "damping": 0.05, "pole_frequency_hz": 350.0,
                                 "pole_damping": 0.4}, n, d, w0))

    # The -3 dB band of an infinitely deep notch at f = 100 Hz, width 30 Hz.
    f, width = 100.0, 30.0
    w = 2 * math.pi * f
    zp = width / (2 * f)
    g2 = lambda x: abs(continuous_response([1, 0, w * w], [1, 2 * zp * w, w * w], x)) ** 2 - 0.5
    lo = optimize.brentq(g2, 0.1 * w, w * (1 - 1e-9), xtol=1e-12)
    hi = optimize.brentq(g2, w * (1 + 1e-9), 10 * w, xtol=1e-12)
    band = {"frequency_hz": f, "width_hz": width, "lower_hz": lo / (2 * math.pi), "upper_hz": hi / (2 * math.pi)}

    out = {"source": "tools/reference/drive_filter_reference.py", "ts": TS, "cases": cases, "notch_band": band}
    path = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data", "tuning", "drive_filter_reference.json")
    with open(path, "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
