#!/usr/bin/env bash
# Installs, from Debian's archive, the packages posefuse needs to build its
# tests, examples, benchmarks and Python module (pybind11, Python headers,
# numpy and pytest for its tests) -- and only those that are missing. Safe
# to run again: on a machine that has them all it does nothing.
set -euo pipefail
packages=(cmake g++ make ninja-build libeigen3-dev catch2 libbenchmark-dev
          pybind11-dev python3-dev python3-numpy python3-pytest)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
((${#missing[@]} == 0)) && exit 0
echo "posefuse: installing missing Debian packages: ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "posefuse: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
