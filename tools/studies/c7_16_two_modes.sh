#!/usr/bin/env bash
# Catalog C7.16 (Sec. 7.4): the demo plant of eq. 7.165 (wz1 = 1, xi_z1 = 0.01, w1 = 4, xi_1 = 0.04,
# wz2 = 6, xi_z2 = 0.01, w2 = 12, xi_2 = 0.02; normalized units, the 1 ms sample delay) tuned by
# `servotwin tune` as a PI on the first mode and as the three H-infinity variants (--modes first,
# passive, active), each within Ms = Mt = 1.5 on the full model. Prints each summary;
# docs/controller-tuning-study.md quotes them.
#   tools/studies/c7_16_two_modes.sh [SERVOTWIN]
set -euo pipefail
servotwin=${1:-build/unity/servotwin}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# (s^2 + 0.02 s + 1) (w2^2/wz2^2)(s^2 + 0.12 s + 36) / (s (s^2 + 0.32 s + 16)(s^2 + 0.48 s + 144)), expanded.
cat > "$work/two_modes.json" <<JSON
{"format": "servotwin.plant/1", "type": "transfer-function", "num": [4, 0.56, 148.0096, 3.36, 144],
 "den": [1, 0.8, 160.1536, 53.76, 2304, 0], "noise_std": 0, "ts": 0.001}
JSON
echo "== pi"
"$servotwin" -q tune "$work/two_modes.json" --structure pi -o "$work/pi.json"
for modes in first passive active; do
  echo "== hinf --modes $modes"
  "$servotwin" -q tune "$work/two_modes.json" --structure hinf --modes "$modes" -o "$work/$modes.json"
done
