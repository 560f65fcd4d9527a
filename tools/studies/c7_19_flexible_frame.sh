#!/usr/bin/env bash
# Catalog C7.19 (Sec. 7.6, Fig. 7.43) from the command line: the flexible-frame preset (eq. 7.175 with
# m4 = 0.2, ts 10 ms) tuned as (1) a PI on the first mode, (2) the same PI with a ZV setpoint shaper
# at the loop's frame mode (read from the PI run), (3) an H-infinity on the full model with a
# damping floor of 0.15; each runs the setpoint / load-force / stator-force sequence. Prints each
# summary; docs/controller-tuning-study.md quotes them.
#   tools/studies/c7_19_flexible_frame.sh [SERVOTWIN]
set -euo pipefail
servotwin=${1:-build/unity/servotwin}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$servotwin" -q tune c7.19-frame --structure pi -o "$work/pi.json" > /dev/null
"$servotwin" -q tune c7.19-frame --structure hinf --min-damping 0.15 -o "$work/hinf.json" > /dev/null
echo "== (1) pi"
"$servotwin" -q simulate --controller "$work/pi.json" --test frame-sequence | tee "$work/pi.txt"
# The frame mode: the lightly damped closed-loop mode between 3.5 and 6.5 rad/s.
read -r hz zeta < <(awk '/rad\/s \(/ && $1 > 3.5 && $1 < 6.5 { gsub(/[(),:]/, ""); print $3, $6; exit }' "$work/pi.txt")
"$servotwin" -q shaper design --type zv --freq-hz "$hz" --zeta "$zeta" -o "$work/zv.json" > /dev/null
echo "== (2) pi + zv shaper at $hz Hz, damping $zeta"
"$servotwin" -q simulate --controller "$work/pi.json" --test frame-sequence --shaper "$work/zv.json"
echo "== (3) hinf, --min-damping 0.15"
"$servotwin" -q simulate --controller "$work/hinf.json" --test frame-sequence
