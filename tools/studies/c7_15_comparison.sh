#!/usr/bin/env bash
# The structure comparison of catalog C7.15 across resonance ratios: the normalized frictionless
# two-mass plant (antiresonance 1 rad/s, Im = 1, zeta_z = 0.01, resonance damping r*zeta_z) for
# r in [1.1, 8], each compared by `servotwin tune compare` (PI, PID with r-bar = 2, LQG, H-infinity) at
# Ms = Mt = 1.5. Prints one table per r; docs/controller-tuning-study.md quotes it.
#   tools/studies/c7_15_comparison.sh [SERVOTWIN]
set -euo pipefail
servotwin=${1:-build/unity/servotwin}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for r in 1.1 1.3 1.5 1.7 2 2.3 3 4 5 6 8; do
  # (s^2 + 2 zeta_z s + 1) / (s (s^2 + 2 zeta_z r^2 s + r^2)): zeta_p = r zeta_z, normalized units.
  den=$(awk -v r="$r" 'BEGIN { printf "%.10g, %.10g", 2 * 0.01 * r * r, r * r }')
  cat > "$work/r$r.json" <<JSON
{"format": "servotwin.plant/1", "type": "transfer-function", "num": [1, 0.02, 1], "den": [1, $den, 0],
 "noise_std": 0, "ts": 0.001}
JSON
  echo "== r = $r"
  "$servotwin" -q tune compare "$work/r$r.json" || true
done
