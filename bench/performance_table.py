#!/usr/bin/env python3
"""Issue 26's benchmark table: each measurement beside its reference, medians of >= 5 runs.

    bench/performance_table.py [build directory, default build/release] > table.md

Runs, on this machine:
  * bench_axis_model: the axis-model simulation with friction (thesis PID model, and a model
    faster than the sampling) against the same simulation with the event search on every sample;
  * bench_trace_read: reading a capture CSV from a file against a plain std::from_chars loop;
  * `servotwin identify` with its defaults on a 966 k-row capture (a 9000-move identification
    program run on two virtual machines) against the numpy pipeline of
    bench/reference/identify_reference.py (read, eight regressors, lstsq; its bounded stage is not
    counted), when Debian's python3-numpy and python3-scipy are installed;
  * bench_prediction: the prediction of a ten-minute 3-axis program on every core against the same
    work on one thread, and the prediction CSV writer against std::to_chars into one buffer;
    `servotwin predict -o` writing that CSV (the command's time with -o less its time without);
  * `servotwin identify` on a 1-hour 3-axis capture (every axis): time and peak memory, beside
    the size of the capture's t, cmd and act columns as doubles;
  * bench_machine: the virtual machine with every nonlinearity on against the same loop as a
    linear difference equation;
  * `servotwin frf measure` 1-500 Hz on the motor bench: computer time per 30 s of experiment,
    beside the 30 s the experiment takes on a drive.
Prints a Markdown table (docs/performance.md holds the last one). Standard library only.
"""
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "release")
RUNS = 5


def bench_medians(binary, pattern):
    """Median real time [ms] and bytes/items per second of each benchmark matching pattern."""
    out = subprocess.run([os.path.join(BUILD, "bench", binary), f"--benchmark_filter={pattern}",
                          f"--benchmark_repetitions={RUNS}", "--benchmark_report_aggregates_only=true",
                          "--benchmark_format=json", "--benchmark_min_time=0.2"],
                         check=True, capture_output=True, text=True).stdout
    result = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
        result[b["run_name"]] = {"ms": b["real_time"] * scale, "items": b.get("items_per_second", 0.0),
                                 "bytes": b.get("bytes_per_second", 0.0)}
    return result


def wall_median(command, before=None):
    """Median wall time [s] of a command; `before` (if given) runs ahead of each, untimed."""
    times = []
    for _ in range(RUNS):
        if before:
            before()
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def wall_and_peak_median(command):
    """Median wall time [s] and median peak resident memory [MB] of a command."""
    times, peaks = [], []
    for _ in range(RUNS):
        start = time.perf_counter()
        child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)  # reaped here, for its rusage
        times.append(time.perf_counter() - start)
        if child.returncode != 0:
            raise RuntimeError(f"{command} failed")
        peaks.append(usage.ru_maxrss / 1024.0)  # kB on Linux
    return statistics.median(times), statistics.median(peaks)


def ten_minute_program(path, turns=330):
    """The program of bench_prediction: helical turns, diamonds, F12000."""
    lines = ["G17 G90 G01 X20 Y0 Z0 F12000"]
    for i in range(1, turns + 1):
        lines.append(f"G03 X20 Y0 Z{-0.2 * i:.4f} I-20 J0")
        lines += ["G01 X0 Y20", "G01 X-20 Y0", "G01 X0 Y-20", "G01 X20 Y0"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def three_axis_machine(servotwin, path):
    """fadal-pid with its Y axis copied as Z (the presets have two axes)."""
    exported = subprocess.run([servotwin, "machine", "fadal-pid", "--export"], check=True, capture_output=True,
                              text=True).stdout
    machine = json.loads(exported)
    z = json.loads(json.dumps(machine["axes"][1]))
    z["name"] = "z"
    machine["axes"].append(z)
    with open(path, "w") as f:
        json.dump(machine, f)


def prediction_rows(servotwin, tmp):
    rows = []
    pred = bench_medians("bench_prediction", "PredictTenMinutes/|WritePredictionCsv")
    ours = pred["BM_PredictTenMinutes/0/iterations:5/real_time"]
    one = pred["BM_PredictTenMinutes/1/iterations:5/real_time"]
    rows.append(("`vcnc::predict` of a ten-minute 3-axis program at 1 kHz (604 k samples) with contour error "
                 "(`bench_prediction`)", f"{ours['ms'] / 1e3:.3f} s", f"the same on one thread: {one['ms'] / 1e3:.3f} s",
                 f"{one['ms'] / ours['ms']:.2f}x"))
    writer, ref = pred["BM_WritePredictionCsv/0"], pred["BM_WritePredictionCsv/1"]
    rows.append(("prediction CSV writer, the ten-minute prediction in memory (`bench_prediction`)",
                 f"{writer['bytes'] / 1e6:.0f} MB/s", f"std::to_chars into one buffer: {ref['bytes'] / 1e6:.0f} MB/s",
                 f"{writer['bytes'] / ref['bytes']:.2f}x"))
    program = os.path.join(tmp, "ten.nc")
    ten_minute_program(program)
    # Models: identified from an identification capture of fadal-pid, the same for every axis.
    ident = os.path.join(tmp, "ident.nc")
    subprocess.run([servotwin, "-q", "gcode", "identification", "--axis", "X", "--seed", "7", "-o", ident], check=True)
    capture = os.path.join(tmp, "ident.csv")
    subprocess.run([servotwin, "-q", "capture", "--machine", "fadal-pid", "--program", ident, "-o", capture], check=True)
    identified = os.path.join(tmp, "identified.json")
    subprocess.run([servotwin, "-q", "identify", capture, "--axis", "x", "-o", identified], check=True, capture_output=True)
    with open(identified) as f:
        model = json.load(f)
    models = []
    for axis in "xyz":
        model["axis"] = axis
        path = os.path.join(tmp, f"{axis}.json")
        with open(path, "w") as f:
            json.dump(model, f)
        models += ["--model", path]
    csv = os.path.join(tmp, "prediction.csv")
    remove_csv = lambda: os.path.exists(csv) and os.remove(csv)  # noqa: E731
    without = wall_median([servotwin, "-q", "predict", *models, "-p", program])
    with_csv = wall_median([servotwin, "-q", "predict", *models, "-p", program, "-o", csv], before=remove_csv)
    size = os.path.getsize(csv)
    writing = with_csv - without
    if writing <= 0.0:
        raise RuntimeError(f"predict -o took {with_csv:.3f} s, not more than without -o ({without:.3f} s): rerun")
    rows.append((f"`servotwin predict ... -o` of that program: the {size / 1e6:.0f} MB CSV (time with -o less time "
                 f"without; without: {without:.2f} s whole process)", f"{size / writing / 1e6:.0f} MB/s",
                 f"std::to_chars into one buffer: {ref['bytes'] / 1e6:.0f} MB/s",
                 f"{size / writing / ref['bytes']:.2f}x"))
    os.remove(csv)
    return rows


def hour_capture_rows(servotwin, tmp):
    machine = os.path.join(tmp, "three-axis.json")
    three_axis_machine(servotwin, machine)
    program = os.path.join(tmp, "hour.nc")
    ten_minute_program(program, turns=6 * 330)
    capture = os.path.join(tmp, "hour.csv")
    subprocess.run([servotwin, "-q", "capture", "--machine", machine, "--program", program, "-o", capture], check=True)
    with open(capture) as f:
        rows_in_file = sum(1 for _ in f) - 1
    wall, peak = wall_and_peak_median([servotwin, "-q", "-f", "identify", capture, "-o",
                                       os.path.join(tmp, "hour_{axis}.json")])
    columns_mb = rows_in_file * 7 * 8 / 1e6
    size_mb = os.path.getsize(capture) / 1e6
    os.remove(capture)
    return [(f"`servotwin identify` of a 1-hour 3-axis capture, every axis ({rows_in_file / 1e6:.1f} M rows, "
             f"{size_mb:.0f} MB of CSV with the drive outputs), whole process", f"{wall:.2f} s, peak {peak:.0f} MB",
             f"t, cmd and act of 3 axes as doubles: {columns_mb:.0f} MB", f"{columns_mb / peak:.2f}x")]


def machine_and_frf_rows(servotwin, tmp):
    rows = []
    vm = bench_medians("bench_machine", "SimulatePid$|SimulatePolePlacementZpetc|LinearClosedLoopReference")
    ref = vm["BM_LinearClosedLoopReference"]
    for name, label in (("BM_SimulatePid", "fadal-pid"), ("BM_SimulatePolePlacementZpetc", "ballscrew-zpetc")):
        rows.append((f"virtual machine {label}, every nonlinearity on, 22 s of 2 axes (`bench_machine`)",
                     f"{vm[name]['items'] / 1e6:.1f} M samples/s per axis",
                     f"fadal-pid's loop as a linear difference equation: {ref['items'] / 1e6:.0f} M samples/s",
                     f"{vm[name]['items'] / ref['items']:.2f}x"))
    out = os.path.join(tmp, "frf.csv")
    remove = lambda: os.path.exists(out) and os.remove(out)  # noqa: E731
    command = [servotwin, "frf", "measure", "--plant", "motor-bench", "--range-hz", "1:500", "-o", out]
    wall = wall_median(command, before=remove)
    run = subprocess.run([servotwin, "-f", "frf", "measure", "--plant", "motor-bench", "--range-hz", "1:500", "-o", out],
                         check=True, capture_output=True, text=True)
    experiment = float(re.search(r"in ([0-9.]+) s of experiment", run.stdout + run.stderr).group(1))
    per_30 = wall * 30.0 / experiment
    rows.append((f"`servotwin frf measure --plant motor-bench --range-hz 1:500` ({experiment:.1f} s of experiment), "
                 "whole process", f"{per_30:.2f} s per 30 s of experiment", "the experiment on a drive: 30 s",
                 f"{30.0 / per_30:.0f}x"))
    return rows


def numpy_pipeline_median(capture):
    """Median of read + regressors + lstsq [s], or None without numpy/scipy."""
    script = os.path.join(ROOT, "bench", "reference", "identify_reference.py")
    times = []
    for _ in range(RUNS):
        run = subprocess.run(["/usr/bin/python3", script, capture, "--axis", "x"], capture_output=True, text=True)
        if run.returncode != 0:
            return None
        t = json.loads(run.stdout)["time_ms"]
        times.append((t["read"] + t["regressors_and_statistics"] + t["ls"]) / 1e3)
    return statistics.median(times)


def main():
    rows = []
    sim = bench_medians("bench_axis_model", "Reused|EverySample")
    for name, label in (("BM_SimulatePidFriction22sReused", "thesis PID model (Table 3.4)"),
                        ("BM_SimulateFastPairFriction22sReused", "143 Hz pair, zeta 0.2, p 0.2 Hz (faster than the sampling)")):
        ref = sim[name.replace("Reused", "EverySample")]
        rows.append((f"axis-model simulation with friction, 22 s at 1 kHz, {label} (`bench_axis_model`)",
                     f"{sim[name]['items'] / 1e6:.1f} M samples/s",
                     f"event search on every sample: {ref['items'] / 1e6:.1f} M samples/s",
                     f"{ref['ms'] / sim[name]['ms']:.1f}x"))
    read = bench_medians("bench_trace_read", "ServotwinCapture|FromCharsLoop")
    ours, ref = read["BM_ReadServotwinCapture"], read["BM_FromCharsLoopReference"]
    rows.append(("reading a 600 k-row, 3-axis capture CSV from a file (`bench_trace_read`)",
                 f"{ours['bytes'] / 1e6:.0f} MB/s", f"read + std::from_chars loop: {ref['bytes'] / 1e6:.0f} MB/s",
                 f"{ours['bytes'] / ref['bytes']:.2f}x"))
    servotwin = os.path.join(BUILD, "servotwin")
    with tempfile.TemporaryDirectory() as tmp:
        program = os.path.join(tmp, "long.nc")
        subprocess.run([servotwin, "-q", "gcode", "identification", "--axis", "X", "--moves", "9000", "--seed", "3",
                        "-o", program], check=True)
        for machine in ("fadal-pid", "ballscrew-zpetc"):
            capture = os.path.join(tmp, f"{machine}.csv")
            subprocess.run([servotwin, "-q", "capture", "--machine", machine, "--program", program, "-o", capture],
                           check=True)
            ours = wall_median([servotwin, "-q", "-f", "identify", capture, "--axis", "x", "-o",
                                os.path.join(tmp, "model.json")])
            reference = numpy_pipeline_median(capture)
            rows.append((f"`servotwin identify capture.csv --axis x` (defaults), 966 k rows from {machine}, whole process",
                         f"{ours:.2f} s",
                         "numpy read + regressors + lstsq: " + (f"{reference:.2f} s" if reference else "(numpy not installed)"),
                         f"{reference / ours:.2f}x" if reference else ""))
        rows += prediction_rows(servotwin, tmp)
        rows += hour_capture_rows(servotwin, tmp)
        rows += machine_and_frf_rows(servotwin, tmp)
    print("| measurement | this machine (median of 5) | reference, same run | ratio |")
    print("|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
