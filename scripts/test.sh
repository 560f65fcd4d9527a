#!/usr/bin/env bash
# One command for developers and CI: install what is missing, build everything (Release, warnings
# as errors) and run the tests of the release binaries with CTest, then build with address +
# undefined sanitizers and run every C++ test there, then build the libFuzzer targets with clang
# and run each on 20 000 inputs from a fixed seed. `--quick` skips the sanitizer pass and runs every test in the release build.
set -euo pipefail
cd "$(dirname "$0")/.."
asan=1
for arg in "$@"; do
  case "$arg" in
    --quick) asan=0 ;;
    *) echo "test.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done
scripts/install-deps.sh --test

started=$SECONDS
# Minutes and seconds since the start, for the stage lines (CI's budget is 50 minutes).
elapsed() { printf '%d:%02d' $(((SECONDS - started) / 60)) $(((SECONDS - started) % 60)); }

run_preset() {
  local preset=$1 unit_tests=$2
  echo "== configure and build ($preset), at $(elapsed)"
  cmake --preset "$preset" -DSERVOTWIN_BUILD_TESTS=ON -DSERVOTWIN_UNIT_TESTS="$unit_tests" >/dev/null
  cmake --build --preset "$preset"
  echo "== test ($preset), at $(elapsed)"
  ctest --preset "$preset" 2>&1 | tee "build/$preset/ctest.log" | grep -vE "^ +Start|^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* Passed" || true
  echo "== $preset done at $(elapsed)"
  # ctest's summary (the lines after the per-test list) decides the exit status.
  grep -q "100% tests passed" "build/$preset/ctest.log"
}

# The per-module unit tests (tests/<module>, about 1100 of the 1180 tests) run once, in the
# sanitizer pass: compiling them twice cost CI's 50-minute budget about eight minutes, and the
# sanitizers see in them what the release build would not. The release pass builds the product
# (library, CLI, benchmarks) with warnings as errors and runs what tests the release binaries: the
# CLI end to end, LinuxCNC integration, the HTML reports in a browser, the installed package, the
# study table and the layering check. `--quick` runs everything in the release pass instead.
if [ "$asan" -eq 1 ]; then
  run_preset release OFF
else
  run_preset release ON
fi
# The asan pass leaves out the headless-Chromium checks of the HTML reports (report.browser.*):
# they test what a browser renders, which the sanitizers cannot see, and cost about a minute and a
# half of the 50-minute budget; the C++ that writes the reports runs under asan in the report and
# CLI tests.
if [ "$asan" -eq 1 ]; then
  run_preset asan ON
fi
# Fuzz smoke (issue 27 §5): every reader's libFuzzer target, built with clang, runs 20 000 inputs
# from seed 1 on its corpus; a crash, leak or timeout fails the command. The corpora and past
# findings also replay in the unit tests.
echo "== fuzz smoke, at $(elapsed)"
scripts/fuzz-smoke.sh 20000
echo "== fuzz smoke done at $(elapsed)"
