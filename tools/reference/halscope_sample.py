#!/usr/bin/env python3
"""Writes data/profiles/samples/linuxcnc-halscope.csv: the LinuxCNC trace excerpt
data/profiles/samples/linuxcnc-servotwin-rig.txt (halsampler -t output of the integration rig,
integration/linuxcnc/) laid out as LinuxCNC 2.9's halscope writes its log file ("Save Log",
write_log_file() in src/hal/utils/scope_files.c):

    fprintf(fp, "# Sampling period is %i ns\\n", sample_period_ns);   (thread period x HMULT)
    channel names, in channel order, joined by ';' (no trailing ';')
    one row per sample, values printed "%.14f" under the C locale, joined by ';'

The channels are the pins the rig's sampler records for X and Y (servotwin_sim.hal's nets):
joint.N.motor-pos-cmd, joint.N.motor-pos-fb, pid.A.output. halscope itself is a GUI program and
was not run: this file follows the format strings of its source, it is not a recording of it.
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = os.path.join(HERE, "..", "..", "data", "profiles", "samples")
NAMES = ["joint.0.motor-pos-cmd", "joint.0.motor-pos-fb", "pid.x.output",
         "joint.1.motor-pos-cmd", "joint.1.motor-pos-fb", "pid.y.output"]

with open(os.path.join(SAMPLES, "linuxcnc-servotwin-rig.txt")) as f:
    rows = [line.split() for line in f if line.strip()]
with open(os.path.join(SAMPLES, "linuxcnc-halscope.csv"), "w") as out:
    out.write("# Sampling period is %i ns\n" % 1000000)
    out.write(";".join(NAMES) + "\n")
    for r in rows:
        values = [float(v) for v in r[1:7]]  # after the sample number: x cmd, fb, force, y cmd, fb, force
        out.write(";".join("%.14f" % v for v in values) + "\n")
