#!/usr/bin/env bash
# Fuzz smoke stage of the test command (issue 27 §5): builds every libFuzzer target with clang
# (preset "fuzz": address + undefined sanitizers, the libraries instrumented) and runs each for a
# bounded time on a scratch copy of its corpus; any crash, leak, timeout or out-of-memory fails the
# stage, and libFuzzer leaves the input in build/fuzz/artifacts/. Longer runs for development:
#   build/fuzz/fuzz/fuzz_plant fuzz/corpus/plant -max_total_time=600
#   scripts/fuzz-smoke.sh [seconds per target, default 10]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-10}
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
artifacts=build/fuzz/artifacts
mkdir -p "$artifacts"
failed=()
for target in build/fuzz/fuzz/fuzz_*; do
  [ -x "$target" ] || continue
  name=${target##*/fuzz_}
  corpus=fuzz/corpus/$name
  [ "$name" = interpolation ] && corpus=fuzz/corpus/gcode  # the G-code seeds, through the interpolator
  work=build/fuzz/work/$name
  mkdir -p "$work"
  dict=()
  [ "$name" = gcode ] || [ "$name" = interpolation ] && dict=(-dict=fuzz/gcode.dict)
  # New inputs go to the scratch folder (first); the committed seeds (second) are only read.
  if "$target" "$work" "$corpus" "${dict[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix="$artifacts/${name}-" -print_final_stats=0 > "build/fuzz/$name.log" 2>&1; then
    echo "fuzz_$name: $(grep -Eo 'Done [0-9]+ runs in [0-9]+ second' "build/fuzz/$name.log" | tail -n 1 || true)s, no finding"
  else
    echo "fuzz_$name: FAILED (log: build/fuzz/$name.log, input: $artifacts/${name}-*)"
    tail -30 "build/fuzz/$name.log"
    failed+=("$name")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz smoke: failures in ${failed[*]}" >&2
  exit 1
fi
