#!/usr/bin/env bash
# End to end: `servotwin frf measure` on the motor-bench preset, then `servotwin fit --report`, and
# the report is opened in headless Chromium by report_browser_check (exit 77 = Chromium missing:
# CTest skips).
#   fit_report.sh SERVOTWIN REPORT_BROWSER_CHECK WORK_DIR
set -euo pipefail
servotwin=$1
check=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$servotwin" -q frf measure --plant motor-bench --range-hz 1:500 -o frf.csv
"$servotwin" -q fit frf.csv --delay -o plant_model.json --report fit.html
exec "$check" --check fit.html
