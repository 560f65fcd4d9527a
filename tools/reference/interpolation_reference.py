#!/usr/bin/env python3
"""Reference trajectories for the servotwin interpolator tests (tests/motion/test_interpolation_reference.cpp).

How to run (from the repository root; needs python3 with numpy and scipy, written against
numpy 1.24 / scipy 1.10 as shipped by Debian 12):

    python3 tools/reference/interpolation_reference.py           # writes tests/data/motion/interpolation_reference.json
    python3 tools/reference/interpolation_reference.py -o FILE   # writes somewhere else

Deterministic (fixed inputs). Floats are written with Python's shortest round-trip repr.

The interpolator is re-implemented here independently of the C++ code, from the definitions:

  * single moves with a jerk limit (lines, arcs, helices): the closed-form double-S profile with
    zero boundary speed and acceleration (Biagiotti & Melchiorri, "Trajectory Planning for
    Automatic Machines and Robots", Springer 2008, sec. 3.4), covering the cases where the
    acceleration limit and/or the feed are not reached; the position is the exact integral of
    the piecewise-constant jerk (numpy polynomials);
  * chains of segments without a jerk limit (different feeds, a tangent line -> arc transition):
    the time-optimal speed along the path as the pointwise minimum of the speed limit, the
    forward-reachable speed sqrt(v_in^2 + 2 a (s - s_i)) and the backward-reachable speed
    (the distance-domain "velocity envelope"), cross-checked against a brute-force forward /
    backward sweep on a grid of 2e5 cells per segment;
  * arc speed limits: v <= sqrt(sqrt(1 - r^2) accel / kappa) and, with a jerk limit, the positive
    real root (numpy.roots) of kappa*sqrt(kappa^2 + tau^2) v^3 + 3 kappa (r accel) v - (1 - r) jerk
    (kappa, tau: curvature and torsion of the circle or helix); tangential accel r * accel, jerk
    r * jerk (r = arc_tangential_ratio);
  * time scaling onto samples: N = ceil(T / ts), sample m at unscaled time m T / N; the last
    sample is the programmed end point.

Positions: lines start + s * direction; arcs centre + R (cos, sin) in the plane's (first, second)
axes (G17 XY, G18 ZX, G19 YZ, CCW = positive angle), helical rise linear in the angle.
"""

import argparse
import json
import math
import os
import platform
import sys

import numpy as np
import scipy

PLANE_AXES = {"XY": (0, 1, 2), "ZX": (2, 0, 1), "YZ": (1, 2, 0)}


# ---------------------------------------------------------------- double-S (jerk limited)

def double_s_phases(length, vmax, amax, jmax):
    """Phases (duration, jerk) of the time-optimal rest-to-rest double-S move (B&M sec. 3.4)."""
    # Acceleration part to reach vmax (B&M eq. 3.19 with v0 = v1 = 0).
    if vmax * jmax >= amax * amax:
        tj = amax / jmax
        ta = tj + vmax / amax
    else:
        tj = math.sqrt(vmax / jmax)
        ta = 2.0 * tj
    tv = length / vmax - ta  # symmetric deceleration: cruise time
    if tv <= 0.0:
        # Feed not reached (B&M eq. 3.25-3.26 with v0 = v1 = 0).
        tv = 0.0
        tj = amax / jmax
        delta = amax ** 4 / jmax ** 2 + 4.0 * amax * length  # = 2 amax^2 (2 tj^2 ... ) form for v0=v1=0
        ta = (amax ** 2 / jmax + math.sqrt(delta)) / (2.0 * amax)
        if ta < 2.0 * tj:
            # Acceleration limit not reached either (B&M eq. 3.27 with v0 = v1 = 0).
            tj = (length / (2.0 * jmax)) ** (1.0 / 3.0)
            ta = 2.0 * tj
    hold = ta - 2.0 * tj
    return [(tj, jmax), (hold, 0.0), (tj, -jmax), (tv, 0.0), (tj, -jmax), (hold, 0.0), (tj, jmax)]


def jerk_phases_to_polys(phases):
    """Piecewise polynomials s(t) from (duration, jerk) phases starting at rest."""
    out = []
    t = 0.0
    s, v, a = 0.0, 0.0, 0.0
    for d, j in phases:
        if d <= 0.0:
            continue
        out.append((t, t + d, s, v, a, j))
        s = s + v * d + a * d * d / 2.0 + j * d ** 3 / 6.0
        v = v + a * d + j * d * d / 2.0
        a = a + j * d
        t += d
    return out, t


# ---------------------------------------------------------------- velocity envelope (no jerk)

def envelope_phases(segments):
    """segments: list of (length, vmax, accel, cap_at_start); rest at both ends.

    Returns phases (t0, t1, s0, v0, a0, 0) in chain distance and the duration."""
    n = len(segments)
    starts = np.concatenate([[0.0], np.cumsum([sg[0] for sg in segments])])
    # Forward reachable speed at the start of each segment, backward at the end.
    f_in = [0.0] * n
    v = 0.0
    for i, (ln, vm, a, cap) in enumerate(segments):
        v = 0.0 if i == 0 else min(v, cap, vm, segments[i - 1][1])
        f_in[i] = v
        v = min(vm, math.sqrt(v * v + 2.0 * a * ln))
    b_out = [0.0] * n
    v = 0.0
    for i in range(n - 1, -1, -1):
        ln, vm, a, _ = segments[i]
        v = 0.0 if i == n - 1 else min(v, segments[i + 1][3], vm, segments[i + 1][1])
        b_out[i] = v
        v = min(vm, math.sqrt(v * v + 2.0 * a * ln))
    # The envelope of each segment: up to three regions (forward parabola, limit, backward).
    phases = []
    t = 0.0
    for i, (ln, vm, a, _) in enumerate(segments):
        s0 = starts[i]
        vin = min(f_in[i], math.sqrt(b_out[i] ** 2 + 2 * a * ln))  # both envelopes hold at the start
        vout = min(b_out[i], math.sqrt(f_in[i] ** 2 + 2 * a * ln))
        x1 = (vm * vm - vin * vin) / (2 * a)          # forward parabola reaches vm
        x2 = ln - (vm * vm - vout * vout) / (2 * a)   # backward parabola leaves vm
        if x1 > x2:  # no cruise: parabolas cross
            x1 = x2 = (vout * vout - vin * vin + 2 * a * ln) / (4 * a)
            vpk = math.sqrt(vin * vin + 2 * a * x1)
        else:
            vpk = vm
        # (start, end, speed at start, speed at end, acceleration); durations from the speed
        # change (not from a square root of a vanishing difference).
        regions = [(0.0, x1, vin, vpk, a), (x1, x2, vpk, vpk, 0.0), (x2, ln, vpk, vout, -a)]
        for xa, xb, va, vb, acc in regions:
            if xb - xa <= 0.0:
                continue
            d = (xb - xa) / va if acc == 0.0 else (vb - va) / acc
            phases.append((t, t + d, s0 + xa, va, acc, 0.0))
            t += d
    return phases, t


def brute_force_time(segments, cells=200000):
    """Minimum time on a grid: forward / backward sweeps of v^2 on cells of each segment."""
    edges = []
    vmax = []
    acc = []
    caps = []
    for ln, vm, a, cap in segments:
        k = cells
        edges.append(np.full(k, ln / k))
        vmax.append(np.full(k, vm))
        acc.append(np.full(k, a))
        c = np.full(k + 1, np.inf)
        c[0] = cap
        caps.append(c[:-1])
    ds = np.concatenate(edges)
    vm = np.concatenate(vmax)
    a = np.concatenate(acc)
    cap_nodes = np.concatenate(caps)
    m = len(ds)
    limit = np.empty(m + 1)
    limit[:m] = np.minimum(vm, cap_nodes)
    limit[1:m] = np.minimum(limit[1:m], vm[:-1])
    limit[0] = 0.0
    limit[m] = 0.0
    v = limit.copy()
    for k in range(m):
        v[k + 1] = min(v[k + 1], math.sqrt(v[k] ** 2 + 2 * a[k] * ds[k]))
    for k in range(m - 1, -1, -1):
        v[k] = min(v[k], math.sqrt(v[k + 1] ** 2 + 2 * a[k] * ds[k]))
    # Constant acceleration within each cell: time = 2 ds / (v_k + v_k+1).
    return float(np.sum(2 * ds / (v[:-1] + v[1:])))


# ---------------------------------------------------------------- sampling

def poly_position(phases, t):
    for (t0, t1, s, v, a, j) in phases:
        if t <= t1:
            tau = t - t0
            return s + v * tau + a * tau * tau / 2 + j * tau ** 3 / 6
    t0, t1, s, v, a, j = phases[-1]
    tau = t - t0
    return s + v * tau + a * tau * tau / 2 + j * tau ** 3 / 6


def sample_times(duration, ts):
    n = math.ceil(duration / ts)
    assert abs(duration / ts - round(duration / ts)) > 1e-6, "duration too close to a whole number of samples"
    return [m * duration / n for m in range(n + 1)], n


class Line:
    def __init__(self, start, end):
        self.start = np.array(start, float)
        self.end = np.array(end, float)
        self.length = float(np.linalg.norm(self.end - self.start))
        self.dir = (self.end - self.start) / self.length

    def at(self, s):
        return self.start + s * self.dir


class Arc:
    def __init__(self, start, end, center, plane, ccw):
        iu, iv, iw = PLANE_AXES[plane]
        self.axes = (iu, iv, iw)
        self.start = np.array(start, float)
        self.end = np.array(end, float)
        self.center = np.array(center, float)
        su, sv = self.start[iu] - center[iu], self.start[iv] - center[iv]
        eu, ev = self.end[iu] - center[iu], self.end[iv] - center[iv]
        self.radius = math.hypot(su, sv)
        assert abs(math.hypot(eu, ev) - self.radius) < 1e-12 * self.radius
        self.a0 = math.atan2(sv, su)
        sense = 1.0 if ccw else -1.0
        sweep = (sense * (math.atan2(ev, eu) - self.a0)) % (2 * math.pi)
        if sweep == 0.0:
            sweep = 2 * math.pi
        self.sense = sense
        self.sweep = sweep
        self.rise = (self.end[iw] - self.start[iw]) / sweep  # per radian
        self.length = sweep * math.hypot(self.radius, self.rise)
        g2 = self.radius ** 2 + self.rise ** 2
        self.kappa = self.radius / g2
        self.tau = self.rise / g2

    def at(self, s):
        iu, iv, iw = self.axes
        phi = s / math.hypot(self.radius, self.rise)
        ang = self.a0 + self.sense * phi
        p = self.start.copy()
        p[iu] = self.center[iu] + self.radius * math.cos(ang)
        p[iv] = self.center[iv] + self.radius * math.sin(ang)
        p[iw] = self.start[iw] + self.rise * phi
        return p

    def limits(self, feed, accel, jerk, ratio):
        v = min(feed, math.sqrt(math.sqrt(1 - ratio ** 2) * accel / self.kappa))
        if jerk is not None:
            k3 = self.kappa * math.hypot(self.kappa, self.tau)
            roots = np.roots([k3, 0.0, 3 * self.kappa * ratio * accel, -(1 - ratio) * jerk])
            real = [r.real for r in roots if abs(r.imag) < 1e-9 * abs(r) and r.real > 0]
            assert len(real) == 1
            v = min(v, real[0])
        return v, ratio * accel, None if jerk is None else ratio * jerk


# ---------------------------------------------------------------- cases

def block(kind, start, end, feed, center=None, plane="XY"):
    return {"type": kind, "start": list(start), "end": list(end), "center": list(center or [0, 0, 0]),
            "plane": plane, "feed_mm_min": feed}


def make_case(name, blocks, limits, note):
    ts = limits["ts"]
    accel = limits["accel"]
    jerk = limits.get("jerk")
    ratio = limits.get("arc_tangential_ratio", 0.5)
    geos = []
    for b in blocks:
        if b["type"] == "linear":
            geos.append(Line(b["start"], b["end"]))
        else:
            geos.append(Arc(b["start"], b["end"], b["center"], b["plane"], b["type"] == "arc_ccw"))
    seg_limits = []
    for b, g in zip(blocks, geos):
        feed = b["feed_mm_min"] / 60.0
        if isinstance(g, Line):
            seg_limits.append((feed, accel, jerk))
        else:
            seg_limits.append(g.limits(feed, accel, jerk, ratio))
    if jerk is not None:
        assert len(geos) == 1, "jerk-limited reference only for single moves"
        v, a, j = seg_limits[0]
        phases, duration = jerk_phases_to_polys(double_s_phases(geos[0].length, v, a, j))
        brute = None
    else:
        # Chains here are tangent or collinear: no junction cap beyond the segment limits.
        segs = [(g.length, v, a, math.inf) for g, (v, a, _) in zip(geos, seg_limits)]
        phases, duration = envelope_phases(segs)
        brute = brute_force_time(segs)
        assert abs(brute - duration) < 1e-4 * duration, (name, brute, duration)
    times, n = sample_times(duration, ts)
    starts = np.concatenate([[0.0], np.cumsum([g.length for g in geos])])
    positions = []
    for m, t in enumerate(times):
        s = poly_position(phases, t)
        if m == n:
            positions.append(list(map(float, geos[-1].end)))
            continue
        i = int(np.searchsorted(starts, s, side="right") - 1)
        i = min(max(i, 0), len(geos) - 1)
        positions.append(list(map(float, geos[i].at(s - starts[i]))))
    return {
        "name": name,
        "note": note,
        "blocks": blocks,
        "limits": limits,
        "duration_unscaled": duration,
        "brute_force_duration": brute,
        "samples": n + 1,
        "positions": positions,
    }


def cases():
    d3 = np.array([2.0, 3.0, 6.0]) / 7.0
    p0 = np.array([1.0, 2.0, 3.0])
    out = []
    lim = {"ts": 0.001, "accel": 2000.0}
    out.append(make_case("line_triangle", [block("linear", p0, p0 + 5.3 * d3, 12000.0)], lim,
                         "3-axis line shorter than v^2/a: triangular speed"))
    out.append(make_case("line_trapezoid", [block("linear", p0, p0 + 123.45 * d3, 12000.0)], lim,
                         "3-axis line reaching the feed"))
    dxy = np.array([0.8, 0.6, 0.0])
    for name, ln, j in [("scurve_feed_and_accel", 100.37, 1e5), ("scurve_feed_only", 100.37, 1e4),
                        ("scurve_accel_only", 8.21, 1e6), ("scurve_neither", 0.317, 1e5)]:
        out.append(make_case(name, [block("linear", [0, 0, 0], ln * dxy, 12000.0)],
                             {"ts": 0.001, "accel": 2000.0, "jerk": j}, "double-S line"))
    arc = [block("arc_ccw", [10, 0, 0], [0, 10, 0], 12000.0, [0, 0, 0], "XY")]
    out.append(make_case("arc_quarter_trapezoid", arc, lim, "quarter circle R 10: arc speed limit binds"))
    out.append(make_case("arc_quarter_scurve", arc, {"ts": 0.001, "accel": 2000.0, "jerk": 1e5},
                         "quarter circle R 10 with jerk: cubic arc speed limit binds"))
    helix = [block("arc_cw", [0, 0, 10], [10, 5, 0], 6000.0, [0, 0, 0], "ZX")]
    out.append(make_case("helix_zx_scurve", helix, {"ts": 0.0005, "accel": 1500.0, "jerk": 4e4},
                         "G18 clockwise three-quarter helix rising 5 mm in Y"))
    two = [block("linear", [0, 0, 0], [30, 0, 0], 12000.0), block("linear", [30, 0, 0], [40, 0, 0], 3000.0)]
    out.append(make_case("collinear_two_feeds", two, lim, "collinear lines F12000 then F3000"))
    tangent = [block("linear", [-20, 0, 0], [0, 0, 0], 12000.0),
               block("arc_ccw", [0, 0, 0], [10, 10, 0], 12000.0, [0, 10, 0], "XY")]
    out.append(make_case("tangent_line_arc", tangent, lim, "line into a tangent quarter circle R 10"))
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default = os.path.join(here, "..", "..", "tests", "data", "motion", "interpolation_reference.json")
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=default)
    args = ap.parse_args()
    data = {
        "format": "servotwin.test-fixture/1",
        "generator": {"script": "tools/reference/interpolation_reference.py", "python": platform.python_version(),
                      "numpy": np.__version__, "scipy": scipy.__version__},
        "cases": cases(),
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    with open(args.output, "w") as f:
        # One case per line keeps the file small and its diffs readable.
        head = {k: v for k, v in data.items() if k != "cases"}
        f.write("{\n")
        for k, v in head.items():
            f.write(f" {json.dumps(k)}: {json.dumps(v)},\n")
        f.write(' "cases": [\n')
        f.write(",\n".join("  " + json.dumps(c, separators=(",", ":")) for c in data["cases"]))
        f.write("\n ]\n}\n")
    print(f"wrote {args.output}: {len(data['cases'])} cases", file=sys.stderr)


if __name__ == "__main__":
    main()
