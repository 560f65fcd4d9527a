#!/usr/bin/env bash
# Fuzz smoke stage of the test command (issue 27 §5): builds every libFuzzer target with clang
# (preset "fuzz": address + undefined sanitizers, the readers instrumented) and runs each for a
# fixed number of inputs from a fixed seed, starting from its committed corpus only. The same
# commit therefore explores the same inputs on every machine: a finding fails the stage here and
# in CI alike, and libFuzzer leaves the input in build/fuzz/artifacts/ (add it to
# tests/data/io/fuzz_regressions/<reader>/ with the fix). The release tree's libraries are
# brought up to date first: build the fuzz preset through this script (or after building the
# release tree), or it links stale ones. Open-ended runs for development:
#   mkdir -p build/fuzz/work/plant
#   build/fuzz/fuzz/fuzz_plant build/fuzz/work/plant fuzz/corpus/plant -max_total_time=600
#   scripts/fuzz-smoke.sh [inputs per target, default 20000]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-20000}
case "$runs" in
  '' | *[!0-9]* | 0*) echo "fuzz-smoke.sh: the number of inputs must be a positive integer, got '$runs'" >&2; exit 2 ;;
esac
# The modules the fuzzers do not look into come from the release build when there is one (brought
# up to date first), instead of being compiled a second time (fuzz/CMakeLists.txt).
prebuilt=
if [ -f build/release/CMakeCache.txt ]; then
  modules=$(sed -n 's/.*"SERVOTWIN_PREBUILT_MODULES": "\([^"]*\)".*/\1/p' CMakePresets.json)
  cmake --build --preset release --target $(printf 'servotwin_%s ' ${modules//;/ }) >/dev/null
  prebuilt=$PWD/build/release/src
fi
cmake --preset fuzz -DSERVOTWIN_PREBUILT_DIR="$prebuilt" >/dev/null
cmake --build --preset fuzz
artifacts=build/fuzz/artifacts
mkdir -p "$artifacts"
failed=()
for target in build/fuzz/fuzz/fuzz_*; do
  [ -x "$target" ] || continue
  name=${target##*/fuzz_}
  corpus=fuzz/corpus/$name
  [ "$name" = interpolation ] && corpus=fuzz/corpus/gcode  # the G-code seeds, through the interpolator
  work=build/fuzz/smoke/$name  # emptied: what earlier runs found would make this run differ
  rm -rf "$work" && mkdir -p "$work"
  dict=()
  [ "$name" = gcode ] || [ "$name" = interpolation ] && dict=(-dict=fuzz/gcode.dict)
  # New inputs go to the scratch folder (first); the committed seeds (second) are only read.
  if "$target" "$work" "$corpus" "${dict[@]}" -seed=1 -runs="$runs" -reload=0 -max_total_time=300 -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix="$artifacts/${name}-" -print_final_stats=0 > "build/fuzz/$name.log" 2>&1; then
    done_line=$(grep -Eo 'Done [0-9]+ runs in [0-9]+ second' "build/fuzz/$name.log" | tail -n 1 || true)
    done_runs=$(echo "$done_line" | grep -Eo '[0-9]+' | head -n 1 || true)
    if [ "${done_runs:-0}" -lt "$runs" ]; then
      # -max_total_time ended the run early: fewer inputs than asked, so not the same everywhere.
      echo "fuzz_$name: FAILED: stopped after ${done_runs:-0} of $runs inputs (300 s limit; log: build/fuzz/$name.log)"
      failed+=("$name")
    else
      echo "fuzz_$name: ${done_line}(s), no finding"
    fi
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
