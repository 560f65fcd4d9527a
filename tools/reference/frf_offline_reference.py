#!/usr/bin/env python3
"""Reference values for the offline FRF estimators (tests/frf/test_offline_h1.cpp).

Each case stores the input and output signals themselves (so the C++ test runs on exactly the
same samples) and scipy.signal's Welch estimates of them:
  f, Pxx = welch(x), Pyy = welch(y), Pxy = csd(x, y), Cxy = coherence(x, y),
all with scaling="density" and the same window / nperseg / noverlap / detrend, and
H1 = Pxy / Pxx. The true response of the filter (scipy.signal.freqz) is stored as well.

Cases (seeded, numpy default_rng):
  noise_hann:   white noise through an IIR resonance + output noise; hann, 256, 50 %, constant
  chirp_linear: linear chirp 1-400 Hz (+ small input noise) through the same filter; hann, 200
                (not a power of two), 100 overlap, detrend linear
  noise_boxcar: the noise_hann signals; boxcar window, 256, no overlap, no detrend

Run: /usr/bin/python3 tools/reference/frf_offline_reference.py  (writes tests/data/frf/h1_reference.json)
"""
import json
import pathlib

import numpy as np
from scipy import signal

FS = 1000.0
B = [0.1, 0.05, 0.02]
A = [1.0, -1.6, 0.9]


def estimates(x, y, window, nperseg, noverlap, detrend):
    kw = dict(fs=FS, window=window, nperseg=nperseg, noverlap=noverlap, detrend=detrend, scaling="density")
    f, pxx = signal.welch(x, **kw)
    _, pyy = signal.welch(y, **kw)
    _, pxy = signal.csd(x, y, **kw)
    _, cxy = signal.coherence(x, y, fs=FS, window=window, nperseg=nperseg, noverlap=noverlap, detrend=detrend)
    _, h_true = signal.freqz(B, A, worN=f, fs=FS)
    h1 = pxy / pxx
    return {
        "window": window, "nperseg": nperseg, "noverlap": noverlap,
        "detrend": detrend if detrend else "none",
        "f": f.tolist(), "pxx": pxx.tolist(), "pyy": pyy.tolist(),
        "pxy_re": pxy.real.tolist(), "pxy_im": pxy.imag.tolist(), "coherence": cxy.tolist(),
        "h1_re": h1.real.tolist(), "h1_im": h1.imag.tolist(),
        "true_re": h_true.real.tolist(), "true_im": h_true.imag.tolist(),
    }


def main():
    rng = np.random.default_rng(20240611)
    n = 2048
    x_noise = rng.standard_normal(n)
    y_noise = signal.lfilter(B, A, x_noise) + 0.05 * rng.standard_normal(n)

    m = 2000
    t = np.arange(m) / FS
    x_chirp = signal.chirp(t, f0=1.0, t1=t[-1], f1=400.0, method="linear") + 0.01 * rng.standard_normal(m)
    y_chirp = signal.lfilter(B, A, x_chirp) + 0.02 * rng.standard_normal(m)

    cases = {
        "noise_hann": dict(x=x_noise, y=y_noise, **estimates(x_noise, y_noise, "hann", 256, 128, "constant")),
        "chirp_linear": dict(x=x_chirp, y=y_chirp, **estimates(x_chirp, y_chirp, "hann", 200, 100, "linear")),
        "noise_boxcar": dict(x=x_noise, y=y_noise, **estimates(x_noise, y_noise, "boxcar", 256, 0, False)),
    }
    for case in cases.values():
        case["x"] = case["x"].tolist()
        case["y"] = case["y"].tolist()
    out = {"generator": "tools/reference/frf_offline_reference.py", "scipy": __import__("scipy").__version__,
           "fs": FS, "b": B, "a": A, "cases": cases}
    path = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "frf" / "h1_reference.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=None, separators=(",", ":")) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
