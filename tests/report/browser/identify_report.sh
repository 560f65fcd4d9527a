#!/usr/bin/env bash
# End to end: `servotwin identify --report` on a virtual-machine capture, then the report is opened
# in headless Chromium by report_browser_check (exit 77 = Chromium missing: CTest skips).
#   identify_report.sh SERVOTWIN REPORT_BROWSER_CHECK WORK_DIR
set -euo pipefail
servotwin=$1
check=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$servotwin" -q gcode identification --axis X --moves 120 --seed 7 -o id.nc
"$servotwin" -q capture --machine fadal-pid --program id.nc -o capture.csv
"$servotwin" -q gcode identification --axis X --moves 60 --seed 11 -o check.nc
"$servotwin" -q capture --machine fadal-pid --program check.nc -o check.csv
"$servotwin" -q identify capture.csv --validate check.csv --report report.html
# Written whole, and not replaced without --force.
if "$servotwin" -q identify capture.csv --report report.html 2>/dev/null; then
  echo "identify --report replaced an existing file without --force" >&2
  exit 1
fi
"$servotwin" -q --force identify capture.csv --validate check.csv --report report.html
exec "$check" --check report.html
