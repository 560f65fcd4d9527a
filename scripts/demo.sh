#!/usr/bin/env bash
# One command for a new user: install what is missing, build (Release) and run `servotwin demo`,
# which also writes its HTML report to build/servotwin-demo.html (replaced on every run).
# Extra arguments go to the demo, e.g. scripts/demo.sh --machine fadal-ppi
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release -DSERVOTWIN_BUILD_TESTS=OFF -DSERVOTWIN_BUILD_BENCH=OFF >/dev/null
cmake --build --preset release --target servotwin_cli
exec build/release/servotwin --force demo --report build/servotwin-demo.html "$@"
