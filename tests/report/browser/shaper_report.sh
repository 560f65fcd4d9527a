#!/usr/bin/env bash
# End to end: `servotwin shaper design` for four shapers (two design frequencies), then
# `servotwin shaper compare --report`, and the report is opened in headless Chromium by
# report_browser_check (exit 77 = Chromium missing: CTest skips).
#   shaper_report.sh SERVOTWIN REPORT_BROWSER_CHECK WORK_DIR
set -euo pipefail
servotwin=$1
check=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$servotwin" -q shaper design --type zv --freq-hz 40 --zeta 0.1 -o zv.json > /dev/null
"$servotwin" -q shaper design --type mzv --freq-hz 40 --zeta 0.1 -o mzv.json > /dev/null
"$servotwin" -q shaper design --type 2hump_ei --freq-hz 40 --zeta 0.1 -o 2hump_ei.json > /dev/null
"$servotwin" -q shaper design --type zv4 --preset zvd --freq-hz 25 --zeta 0.02 -o zv4.json > /dev/null
"$servotwin" -q shaper compare zv.json mzv.json 2hump_ei.json zv4.json --report shapers.html > /dev/null
exec "$check" --check shapers.html
