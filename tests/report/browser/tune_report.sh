#!/usr/bin/env bash
# End to end: `servotwin tune --report` on the table-5.1 preset with the P position loop (every
# section but the robustness charts) and on the motor-bench preset with an automatic omega* and an
# uncertainty weight (the scan and robustness charts); then `servotwin simulate --report` of the
# motor-bench PI on its preset (load step with a torque limit); the LQG of table-5.1 with a W2 and
# its simulation; the structure comparison (C7.15) of table-5.1. The reports are opened in headless
# Chromium by report_browser_check (exit 77 = Chromium missing: CTest skips).
#   tune_report.sh SERVOTWIN REPORT_BROWSER_CHECK WORK_DIR
set -euo pipefail
servotwin=$1
check=$2
work=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work"
"$servotwin" -q tune table-5.1 --structure pi+p --report r.html
"$servotwin" -q tune motor-bench --w2-num 0.3,0 --w2-den 1,2000 --report w2.html
"$servotwin" -q tune motor-bench -o pi.json
"$servotwin" -q simulate --controller pi.json --test load-step --amplitude 0.05 --torque-limit 0.5 --report sim.html
# W2 in rad/s for table-5.1 (antiresonance 1 rad/s): 10 % rising to 100 % above ~3 rad/s.
"$servotwin" -q tune table-5.1 --structure lqg --w2-num 0.333,0.1 --w2-den 0.333,1 -o lqg.json --report lqg.html
"$servotwin" -q simulate --controller lqg.json --report lqg_sim.html
"$servotwin" -q tune compare table-5.1 --report compare.html
exec "$check" --check r.html w2.html sim.html lqg.html lqg_sim.html compare.html
