#!/usr/bin/env bash
# End to end: the reports of `servotwin demo --report` and `servotwin predict --report` (with a
# measured capture), opened in headless Chromium by report_browser_check (exit 77 = Chromium
# missing: CTest skips).
#   demo_report.sh SERVOTWIN REPORT_BROWSER_CHECK WORK_DIR
set -euo pipefail
servotwin=$1
check=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$servotwin" -q demo --ga-generations 20 --out run --report demo.html > /dev/null
"$servotwin" -q capture --machine fadal-pid --program run/diamond.nc -o measured.csv
"$servotwin" -q predict --model run/model_x.json --model run/model_y.json --program run/diamond.nc --machine fadal-pid \
  --capture measured.csv --report predict.html > /dev/null
exec "$check" --check demo.html predict.html
