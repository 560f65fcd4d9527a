#!/bin/sh
# Runs the C++ identification pipeline (bench_identify) and the numpy/scipy reference
# (identify_reference.py) on the same EMPS capture and prints both times and their ratio.
# Usage: bench/reference/compare_identify.sh [build directory, default build/release]
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build/release}
capture="$root/data/emps/DATA_EMPS.csv"
cpp=$("$build/bench/bench_identify" --benchmark_filter='BM_IdentifyEmps/search_shift:0' --benchmark_format=json \
  --benchmark_min_time=0.5 2>/dev/null | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["benchmarks"][0]["real_time"])')
python_ms=$(for i in 1 2 3; do /usr/bin/python3 "$root/bench/reference/identify_reference.py" "$capture" --axis x \
  --map x_cmd=qg --map x_act=qm --scale 1000 | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["time_ms"]["total"])'; done | sort -n | head -1)
/usr/bin/python3 - "$cpp" "$python_ms" <<'PY'
import sys
cpp, py = float(sys.argv[1]), float(sys.argv[2])
print(f"identify EMPS (24841 samples): servotwin {cpp:.1f} ms, numpy/scipy {py:.1f} ms (best of 3), ratio {py / cpp:.1f}x")
PY
