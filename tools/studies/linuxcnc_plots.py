#!/usr/bin/env python3
"""Plots of docs/linuxcnc-study.md from a run of integration/linuxcnc/loop.py (stdlib only: SVG).

  tools/studies/linuxcnc_plots.py LOOP_DIR docs/images

For each validation program of the loop (circle, diamond, polygon_g64): the contour error over
time, LinuxCNC's measured one (the trace's feedback against the programmed path) and servotwin's
prediction from LinuxCNC's recorded command, and their difference. Writes
linuxcnc_<program>_contour.svg.
"""
import csv
import math
import os
import sys

W, H = 900, 330
LEFT, RIGHT, TOP, BOTTOM = 70, 20, 34, 46
SERIES = (("contour_err_meas", "LinuxCNC, measured", "#c0392b", 2.2),
          ("contour_err", "servotwin, predicted from LinuxCNC's command", "#1e8449", 1.2))


def read(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    rows = [r for r in rows if r["contour_err_meas"] not in ("", "nan")]
    t = [float(r["t"]) for r in rows]
    return t, {key: [1000.0 * float(r[key]) for r in rows] for key, *_ in SERIES}


def nice_step(span, target=6):
    raw = span / target
    mag = 10 ** math.floor(math.log10(raw))
    for m in (1, 2, 2.5, 5, 10):
        if m * mag >= raw:
            return m * mag
    return 10 * mag


def decimate(t, y, budget=1500):
    """Min and max per bucket: peaks survive."""
    if len(t) <= budget:
        return list(zip(t, y))
    out = []
    size = len(t) / (budget / 2)
    i = 0.0
    while int(i) < len(t):
        a, b = int(i), min(len(t), int(i + size))
        seg = range(a, max(b, a + 1))
        lo = min(seg, key=lambda k: y[k])
        hi = max(seg, key=lambda k: y[k])
        for k in sorted({lo, hi}):
            out.append((t[k], y[k]))
        i += size
    return out


def svg(title, t, series, path):
    x0, x1 = t[0], t[-1]
    values = [v for key, *_ in SERIES for v in series[key]]
    y0, y1 = min(values), max(values)
    pad = 0.05 * (y1 - y0 or 1.0)
    y0, y1 = y0 - pad, y1 + pad
    px = lambda x: LEFT + (x - x0) / (x1 - x0) * (W - LEFT - RIGHT)
    py = lambda y: TOP + (y1 - y) / (y1 - y0) * (H - TOP - BOTTOM)
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" font-family="sans-serif" font-size="12">' % (W, H),
           '<rect width="100%" height="100%" fill="white"/>',
           '<text x="%d" y="20" font-size="14">%s</text>' % (LEFT, title)]
    step = nice_step(y1 - y0)
    v = math.ceil(y0 / step) * step
    while v <= y1:
        out.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="#ddd"/>' % (LEFT, W - RIGHT, py(v), py(v)))
        out.append('<text x="%d" y="%.1f" text-anchor="end">%g</text>' % (LEFT - 6, py(v) + 4, round(v, 6)))
        v += step
    step = nice_step(x1 - x0)
    v = math.ceil(x0 / step) * step
    while v <= x1:
        out.append('<line x1="%.1f" x2="%.1f" y1="%d" y2="%d" stroke="#eee"/>' % (px(v), px(v), TOP, H - BOTTOM))
        out.append('<text x="%.1f" y="%d" text-anchor="middle">%g</text>' % (px(v), H - BOTTOM + 16, round(v, 6)))
        v += step
    out.append('<text x="%d" y="%d" text-anchor="middle">t [s]</text>' % ((LEFT + W - RIGHT) // 2, H - 8))
    out.append('<text x="16" y="%d" transform="rotate(-90 16 %d)" text-anchor="middle">contour error [um]</text>'
               % ((TOP + H - BOTTOM) // 2, (TOP + H - BOTTOM) // 2))
    for i, (key, label, colour, width) in enumerate(SERIES):
        pts = " ".join("%.1f,%.1f" % (px(a), py(b)) for a, b in decimate(t, series[key]))
        out.append('<polyline fill="none" stroke="%s" stroke-width="%.1f" points="%s"/>' % (colour, width, pts))
        out.append('<line x1="%d" x2="%d" y1="%d" y2="%d" stroke="%s" stroke-width="3"/>'
                   % (W - 380, W - 356, TOP + 8 + 16 * i, TOP + 8 + 16 * i, colour))
        out.append('<text x="%d" y="%d">%s</text>' % (W - 350, TOP + 12 + 16 * i, label))
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def main():
    loop, images = sys.argv[1], sys.argv[2]
    titles = {"circle": "Circle, 40 mm at F12000 (G61.1): contour error",
              "diamond": "Diamond, 40 mm at F12000 (G61.1): contour error",
              "polygon_g64": "60-gon and zig-zag, G64 P0.02: contour error against the programmed segments"}
    for name, title in titles.items():
        t, series = read(os.path.join(loop, name + "_prediction.csv"))
        svg(title, t, series, os.path.join(images, "linuxcnc_%s_contour.svg" % name))
        print("wrote " + os.path.join(images, "linuxcnc_%s_contour.svg" % name))


if __name__ == "__main__":
    main()
