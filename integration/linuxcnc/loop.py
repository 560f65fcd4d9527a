#!/usr/bin/env python3
"""servotwin's whole loop on a real CNC controller, LinuxCNC 2.9 (headless, simulated servo axes).

  integration/linuxcnc/loop.py --servotwin build/release/servotwin --out DIR

1. servotwin writes the identification program (thesis Table 3.2: 200 random XY moves within
   +-10 mm at F12000), the thesis's circle and diamond at F12000, in the LinuxCNC dialect; a
   committed program of short segments with G64 blending completes the set.
2. LinuxCNC runs each one (run_program.sh): its interpreter, trajectory planner and servo thread,
   pid loops on simulated tables with viscous and Coulomb friction; halsampler records the joints'
   commanded and actual positions and the pid outputs every servo cycle.
3. servotwin identifies X and Y from the identification trace, read as LinuxCNC wrote it (the
   columns named from the HAL file, the period from the INI file).
4. servotwin predicts each validation program from LinuxCNC's own recorded command, measures the
   contour error against the programmed path, and the prediction is scored against what LinuxCNC
   measured (the trace's feedback).

Targets (issue 24): a stable model; per validation program the predicted contour-error RMS within
10 % of the measured one and the tracking-error NRMSE of each axis <= 0.10. The numbers are
computed here from the prediction CSV (columns <axis>_err, <axis>_meas_err, contour_err,
contour_err_meas), independently of servotwin's own score table. Exit status 0 when every target
holds, 1 when one fails, 2 when a step fails; DIR/summary.json holds the numbers.
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
HAL = os.path.join(HERE, "servotwin_sim.hal")
INI = os.path.join(HERE, "servotwin_sim.ini")
READ = ["--hal", HAL, "--ini", INI]
CONTOUR_TOLERANCE = 0.10   # predicted contour RMS within 10 % of the measured one
NRMSE_LIMIT = 0.10         # tracking-error NRMSE per axis


def step(title, command, cwd, log):
    """Runs one command, its output appended to the log; raises on failure."""
    started = time.monotonic()
    with open(log, "a") as out:
        out.write("\n$ " + " ".join(command) + "\n")
        out.flush()
        result = subprocess.run(command, cwd=cwd, stdout=out, stderr=subprocess.STDOUT)
    elapsed = time.monotonic() - started
    print("  %-52s %6.1f s%s" % (title, elapsed, "" if result.returncode == 0 else "  FAILED (see %s)" % log), flush=True)
    if result.returncode != 0:
        raise RuntimeError("%s failed with status %d; its output is in %s" % (title, result.returncode, log))
    return elapsed


def scores(prediction_csv, axes):
    """Contour RMS (predicted, measured) and per-axis tracking NRMSE over the measured samples."""
    with open(prediction_csv, newline="") as f:
        rows = [r for r in csv.DictReader(row for row in f if not row.startswith("#"))]
    measured = [r for r in rows if r["contour_err_meas"] not in ("", "nan")]
    def rms(values):
        return math.sqrt(sum(v * v for v in values) / len(values))
    out = {"samples": len(measured),
           "contour_rms_predicted": rms([float(r["contour_err"]) for r in measured]),
           "contour_rms_measured": rms([float(r["contour_err_meas"]) for r in measured])}
    out["contour_rms_error"] = abs(out["contour_rms_predicted"] / out["contour_rms_measured"] - 1.0)
    for a in axes:
        e_meas = [float(r[a + "_meas_err"]) for r in measured]
        e_pred = [float(r[a + "_err"]) for r in measured]
        mean = sum(e_meas) / len(e_meas)
        spread = math.sqrt(sum((e - mean) ** 2 for e in e_meas))
        out[a + "_nrmse"] = math.sqrt(sum((m - p) ** 2 for m, p in zip(e_meas, e_pred))) / spread
        out[a + "_tracking_rms_measured"] = rms(e_meas)
        out[a + "_tracking_rms_predicted"] = rms(e_pred)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--servotwin", required=True, help="the servotwin binary")
    parser.add_argument("--out", required=True, help="working directory (created; programs, traces, models, reports)")
    args = parser.parse_args()
    st = os.path.abspath(args.servotwin)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    log = os.path.join(out, "loop.log")
    open(log, "w").close()
    print("servotwin on LinuxCNC: the identification and validation loop (log: %s)" % log, flush=True)
    started = time.monotonic()
    summary = {"targets": {"contour_rms_relative": CONTOUR_TOLERANCE, "tracking_nrmse": NRMSE_LIMIT}, "programs": {}}
    try:
        lc = ["--dialect", "linuxcnc"]
        step("write the identification program", [st, "gcode", "identification", "--axis", "XY", "--moves", "200",
             "--range", "10", "--feed", "12000", "--seed", "7", *lc, "-o", "id.ngc", "--force"], out, log)
        for shape in ("circle", "diamond"):
            step("write the %s" % shape, [st, "gcode", "contour", "--shape", shape, "--size", "40", "--feed", "12000",
                 *lc, "-o", shape + ".ngc", "--force"], out, log)
        shutil.copy(os.path.join(HERE, "programs", "polygon_g64.ngc"), os.path.join(out, "polygon_g64.ngc"))
        programs = ["id", "circle", "diamond", "polygon_g64"]
        for p in programs:
            summary["programs"].setdefault(p, {})["linuxcnc_s"] = step(
                "LinuxCNC runs %s.ngc" % p, [os.path.join(HERE, "run_program.sh"), p + ".ngc", p + ".txt"], out, log)
        step("identify X and Y from LinuxCNC's trace", [st, "identify", "id.txt", *READ, "--program", "id.ngc", *lc,
             "-o", "model_{axis}.json", "--report", "identification.html", "--force"], out, log)
        models = {}
        for a in ("x", "y"):
            with open(os.path.join(out, "model_%s.json" % a)) as f:
                m = json.load(f)
            models[a] = {"stable": m["stable"], "fit_nrmse": m["fit"]["nrmse"], "command_shift": m["regressors"]["command_shift"],
                         "poles": m["poles"]}
        summary["models"] = models
        for p in programs[1:]:
            step("predict %s from LinuxCNC's command" % p,
                 [st, "predict", "--model", "model_x.json", "--model", "model_y.json", "--command", p + ".txt", *READ,
                  "--program", p + ".ngc", *lc, "-o", p + "_prediction.csv", "--report", p + ".html", "--force"], out, log)
            summary["programs"][p].update(scores(os.path.join(out, p + "_prediction.csv"), ("x", "y")))
    except (RuntimeError, OSError, KeyError, ValueError, ZeroDivisionError) as e:
        print("loop.py: " + str(e), file=sys.stderr)
        return 2

    failures = []
    for a, m in summary["models"].items():
        if not m["stable"]:
            failures.append("the %s model is not stable" % a)
    print("\n  %-12s %12s %12s %8s %8s %8s" % ("program", "contour rms", "predicted", "error", "x nrmse", "y nrmse"))
    for p, s in summary["programs"].items():
        if "contour_rms_measured" not in s:
            continue
        print("  %-12s %9.4f mm %9.4f mm %7.1f %% %8.4f %8.4f" % (p, s["contour_rms_measured"], s["contour_rms_predicted"],
                                                          100 * s["contour_rms_error"], s["x_nrmse"], s["y_nrmse"]))
        if s["contour_rms_error"] > CONTOUR_TOLERANCE:
            failures.append("%s: predicted contour RMS %.1f %% off the measured one" % (p, 100 * s["contour_rms_error"]))
        for a in ("x", "y"):
            if s[a + "_nrmse"] > NRMSE_LIMIT:
                failures.append("%s: %s tracking NRMSE %.3f > %.2f" % (p, a, s[a + "_nrmse"], NRMSE_LIMIT))
    for a, m in summary["models"].items():
        print("  model %s: stable %s, fit nrmse %.4f, command shift %d" % (a, m["stable"], m["fit_nrmse"], m["command_shift"]))
    summary["wall_s"] = time.monotonic() - started
    summary["failures"] = failures
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    print("  whole loop %.1f s" % summary["wall_s"])
    for f in failures:
        print("TARGET MISSED: " + f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
