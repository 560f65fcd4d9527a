#!/usr/bin/env python3
"""LinuxCNC's own interpreter reads every program servotwin writes, and reads it as servotwin means.

  integration/linuxcnc/interpreter_check.py --servotwin build/release/servotwin --out DIR

Every generator variant (identification programs of the three thesis sets on one, two and three
axes; circle and diamond; each in the ISO and LinuxCNC dialects and every path-control mode the
dialect can state; the thesis's Heidenhain programs converted to both) is written by servotwin and
run through `rs274` (LinuxCNC's stand-alone interpreter, with the rig's INI). Checked per program:
- the interpreter accepts it (exit status 0, no error line);
- its motion end points (STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED canonical calls) are the
  program's, read here from the program text independently of servotwin;
- its path-control mode (SET_MOTION_CONTROL_MODE) is the one servotwin states: LinuxCNC dialect
  G61.1 = CANON_EXACT_STOP, G61 = CANON_EXACT_PATH, G64 P<t> = CANON_CONTINUOUS with t; an ISO
  program's G61 is exact path for LinuxCNC (the documented dialect difference).
Exit status 0 when all hold, 1 otherwise (each difference printed).
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
INI = os.path.join(HERE, "servotwin_sim.ini")
THESIS_H = os.path.join(HERE, "..", "..", "tests", "data", "motion")

MODES = {  # --path-mode -> expected canonical mode per dialect (None: not stated, LinuxCNC's startup)
    "exact": {"iso": ("CANON_EXACT_PATH", 0.0), "linuxcnc": ("CANON_EXACT_STOP", 0.0)},
    "exact-path": {"linuxcnc": ("CANON_EXACT_PATH", 0.0)},
    "blend": {"iso": ("CANON_CONTINUOUS", 0.0), "linuxcnc": ("CANON_CONTINUOUS", 0.0)},
    "blend:0.02": {"linuxcnc": ("CANON_CONTINUOUS", 0.02)},
    "unstated": {"iso": None, "linuxcnc": None},
}


def program_end_points(text):
    """End point of every motion line of an ISO program servotwin wrote (absolute, modal axes)."""
    pos = [0.0, 0.0, 0.0]
    motion = None
    out = []
    for line in text.splitlines():
        code = re.sub(r"\(.*?\)|;.*", "", line).upper()
        words = re.findall(r"([A-Z])\s*([-+]?[0-9.]+)", code)
        g = [float(v) for k, v in words if k == "G"]
        for v in g:
            if v in (0, 1, 2, 3):
                motion = int(v)
        if 4 in g:
            continue
        axes = {k: float(v) for k, v in words if k in "XYZ"}
        if not axes or motion is None:
            continue
        for i, k in enumerate("XYZ"):
            if k in axes:
                pos[i] = axes[k]
        out.append(tuple(pos))
    return out


def canonical(rs274_output):
    """Motion end points and path-control modes of rs274's canonical calls."""
    points, modes = [], []
    for line in rs274_output.splitlines():
        m = re.search(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|SET_MOTION_CONTROL_MODE)\((.*)\)", line)
        if not m:
            continue
        args = [a.strip() for a in m.group(2).split(",")]
        if m.group(1) == "SET_MOTION_CONTROL_MODE":
            modes.append((args[0], float(args[1]) if len(args) > 1 else 0.0))
        elif m.group(1) == "ARC_FEED":  # G17: first_end, second_end, centre, centre, rotation, axis_end
            points.append((float(args[0]), float(args[1]), float(args[5])))
        else:
            points.append(tuple(float(a) for a in args[:3]))
    return points, modes


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--servotwin", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    st = os.path.abspath(args.servotwin)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    jobs = []  # (file, servotwin arguments, dialect, expected mode)
    for dialect in ("iso", "linuxcnc"):
        for mode, expected in MODES.items():
            if dialect not in expected:
                continue
            tag = "%s-%s" % (dialect, mode.replace(":", "_"))
            for speed, axes in (("standard", "X"), ("low", "XY"), ("high", "XYZ")):
                name = "id-%s-%s-%s.ngc" % (speed, axes, tag)
                jobs.append((name, ["gcode", "identification", "--speed", speed, "--axis", axes, "--seed", "7",
                                    "--dialect", dialect, "--path-mode", mode, "-o", name], expected[dialect]))
            for shape in ("circle", "diamond"):
                name = "%s-%s.ngc" % (shape, tag)
                jobs.append((name, ["gcode", "contour", "--shape", shape, "--dialect", dialect, "--path-mode", mode,
                                    "-o", name], expected[dialect]))
    for h in ("identification_low_x_seed7.h", "identification_high_xy_seed42.h"):
        for dialect in ("iso", "linuxcnc"):
            name = "%s-%s.ngc" % (h[:-2], dialect)
            jobs.append((name, ["gcode", "convert", os.path.join(THESIS_H, h), "--to", dialect, "-o", name], None))
    failures = []
    for name, st_args, expected in jobs:
        write = subprocess.run([st, *st_args, "--force", "-q"], cwd=out, capture_output=True, text=True)
        if write.returncode != 0:
            failures.append("%s: servotwin failed: %s" % (name, write.stderr.strip()))
            continue
        with open(os.path.join(out, name)) as f:
            text = f.read()
        run = subprocess.run(["rs274", "-i", INI, "-g", name], cwd=out, capture_output=True, text=True,
                             stdin=subprocess.DEVNULL, timeout=60)
        if run.returncode != 0:
            failures.append("%s: LinuxCNC's interpreter refuses it: %s" % (name, run.stdout.strip().splitlines()[-3:]))
            continue
        points, modes = canonical(run.stdout)
        ours = program_end_points(text)
        if len(points) != len(ours) or any(max(abs(a - b) for a, b in zip(p, q)) > 1e-4 for p, q in zip(points, ours)):
            failures.append("%s: LinuxCNC moves to %d points, the program to %d (first difference at %s)" % (
                name, len(points), len(ours),
                next((i for i, (p, q) in enumerate(zip(points, ours)) if max(abs(a - b) for a, b in zip(p, q)) > 1e-4),
                     min(len(points), len(ours)))))
        stated = [m for m in modes if m != ("CANON_CONTINUOUS", 0.001 * 25.4)]  # LinuxCNC's startup G64 P0.001 in
        if expected is None:
            if stated:
                failures.append("%s: states no mode, LinuxCNC reads %s" % (name, stated))
        elif not stated or stated[0][0] != expected[0] or abs(stated[0][1] - expected[1]) > 1e-9:
            failures.append("%s: servotwin states %s, LinuxCNC reads %s" % (name, expected, stated))
    print("LinuxCNC's interpreter (rs274) on %d programs written by servotwin: %d differences" % (len(jobs), len(failures)))
    for f in failures:
        print("  " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
