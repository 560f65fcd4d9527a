#!/usr/bin/env bash
# Installs the Debian 12 packages servotwin needs that are not installed yet.
#   scripts/install-deps.sh          build dependencies (compiler, CMake, Eigen, CLI11, fmt, JSON, GLPK, and
#                                    npm, which fetches the charting library of the HTML reports)
#   scripts/install-deps.sh --test   plus GoogleTest/GoogleMock, Google Benchmark, Chromium (the
#                                    reports are checked in headless Chromium), LinuxCNC (the
#                                    integration test runs servotwin's programs on it) and clang
#                                    (the fuzz smoke stage builds the libFuzzer targets)
#   scripts/install-deps.sh --fuzz   plus clang for the libFuzzer targets
set -euo pipefail

packages=(g++ make cmake libeigen3-dev libcli11-dev nlohmann-json3-dev libfmt-dev libglpk-dev)
# npm may also come with a Node.js that is not Debian's (whose package then provides and conflicts
# with Debian's npm): only install Debian's when there is no npm at all.
command -v npm >/dev/null || packages+=(npm)
for arg in "$@"; do
  case "$arg" in
    --test) packages+=(libgtest-dev libgmock-dev libbenchmark-dev python3 chromium linuxcnc-uspace clang libclang-rt-dev) ;;
    --fuzz) packages+=(clang libclang-rt-dev) ;;
    *) echo "install-deps.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps.sh: installing ${missing[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps.sh: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
