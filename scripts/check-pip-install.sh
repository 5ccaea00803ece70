#!/usr/bin/env bash
# The Python package's install round trip, as a user would do it: a fresh
# virtual environment (with the system's site packages, for numpy), then
# `pip install --no-build-isolation .` from this checkout, then
# `import posefuse` and its version, then the tour of docs/python.md on the
# KITTI 06 files of the data folder (skipped, saying so, without them).
# Not part of ctest or CI: it builds the extension from scratch (minutes).
#
# Usage: scripts/check-pip-install.sh [DATA_DIR]
#   DATA_DIR  the data folder (default: $POSEFUSE_DATA_DIR, else ../shared/data
#             beside the checkout)
# Environment: PYTHON (default /usr/bin/python3) creates the venv;
#   CMAKE_BUILD_PARALLEL_LEVEL limits the compile jobs; KEEP=1 keeps the venv.
# Exit status: 0 when everything ran, non-zero at the first failure.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
data=${1:-${POSEFUSE_DATA_DIR:-$root/../shared/data}}
python=${PYTHON:-/usr/bin/python3}
work=$(mktemp -d)
venv=$work/venv
if [[ ${KEEP:-0} == 1 ]]; then echo "check-pip-install: kept: $work"; else trap 'rm -rf "$work"' EXIT; fi

"$python" -m venv --system-site-packages "$venv"
"$venv/bin/python" -m pip install --no-build-isolation --no-deps -q "$root"

want=$(sed -n 's/^project(posefuse VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
got=$(cd / && "$venv/bin/python" -c "import posefuse; print(posefuse.__version__)")
echo "check-pip-install: import posefuse -> $got (installed in $("$venv/bin/python" -c 'import posefuse, os; print(os.path.dirname(posefuse.__file__))'))"
if [[ $got != "$want" ]]; then
  echo "check-pip-install: posefuse.__version__ is '$got', CMakeLists.txt says '$want'" >&2
  exit 1
fi

if [[ ! -f $data/kitti/06/groundtruth.txt ]]; then
  echo "check-pip-install: skipped the docs/python.md tour: no $data/kitti/06 (pass the data folder)"
  exit 0
fi
# The tour's code block from docs/python.md, run in the data folder (it writes ape.json: in a copy).
tour=$work/tour
mkdir -p "$tour"
awk '/^<!-- python-tour -->/ {mark = 1; next} mark && /^```python/ {on = 1; next} on && /^```/ {exit} on {print}' \
  "$root/docs/python.md" >"$tour/tour.py"
[[ -s $tour/tour.py ]] || { echo "check-pip-install: docs/python.md has no <!-- python-tour --> block" >&2; exit 1; }
mkdir -p "$tour/data"
for d in kitti posegraph; do [[ -e $data/$d ]] && ln -s "$(cd "$data/$d" && pwd)" "$tour/data/$d"; done
(cd "$tour/data" && MPLBACKEND=Agg "$venv/bin/python" "$tour/tour.py")
echo "check-pip-install: the docs/python.md tour ran on $data"
