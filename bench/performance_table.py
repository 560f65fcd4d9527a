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
    counted), when Debian's python3-numpy and python3-scipy are installed.
Prints a Markdown table (docs/performance.md holds the last one). Standard library only.
"""
import json
import os
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


def wall_median(command):
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


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
    print("| measurement | this machine (median of 5) | reference, same run | ratio |")
    print("|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
