#!/usr/bin/env bash
# Peak memory of evaluate_trajectory and optimize_pose_graph on large
# generated inputs (docs/programs.md, "Memory"): maximum resident set size
# from GNU time (/usr/bin/time -v), per pose or per node after subtracting a
# run on a 1 000-pose input (program, libraries, small buffers).
#
#   scripts/measure_memory.sh [BUILD_DIR] [POSES]   (defaults: build, 1000000)
#
# Inputs are written to a temporary folder and removed: two TUM files of
# POSES poses on a circle (the estimate displaced by a fixed pattern), and a
# g2o chain of POSES nodes whose vertices are displaced the same way.
set -euo pipefail
build=${1:-build}
n=${2:-1000000}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

tum() {  # tum COUNT DISPLACEMENT > file
  awk -v n="$1" -v d="$2" 'BEGIN {
    for (k = 0; k < n; ++k) {
      a = 0.001 * k
      printf "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", 0.1 * k, 50 * cos(a) + d * sin(7 * k), \
             50 * sin(a) + d * cos(11 * k), sin(a / 2), cos(a / 2)
    } }'
}
chain() {  # chain COUNT > file
  awk -v n="$1" 'BEGIN {
    for (k = 0; k < n; ++k) printf "VERTEX_SE2 %d %.6f %.6f %.6f\n", k, k + 0.5 * sin(7 * k), 0.5 * cos(11 * k), 0.01 * sin(3 * k)
    for (k = 0; k + 1 < n; ++k) printf "EDGE_SE2 %d %d 1 0 0.001 100 0 0 100 0 400\n", k, k + 1
  }'
}
peak_kb() {  # peak_kb COMMAND... : maximum resident set size (kB)
  /usr/bin/time -v "$@" 2>&1 >/dev/null | sed -n 's/^[[:space:]]*Maximum resident set size (kbytes): //p'
}

for count in 1000 "$n"; do
  tum "$count" 0 >"$tmp/gt_$count.tum"
  tum "$count" 0.05 >"$tmp/est_$count.tum"
  chain "$count" >"$tmp/chain_$count.g2o"
done

e_small=$(peak_kb "$build/examples/evaluate_trajectory" --groundtruth "$tmp/gt_1000.tum" --estimate "$tmp/est_1000.tum")
e_large=$(peak_kb "$build/examples/evaluate_trajectory" --groundtruth "$tmp/gt_$n.tum" --estimate "$tmp/est_$n.tum")
echo "evaluate_trajectory: two $n-pose TUM files ($(stat -c %s "$tmp/gt_$n.tum") B each): peak ${e_large} kB," \
  "$(((e_large - e_small) * 1024 / (2 * n))) B per pose read"
g_small=$(peak_kb "$build/examples/optimize_pose_graph" --input "$tmp/chain_1000.g2o")
g_large=$(peak_kb "$build/examples/optimize_pose_graph" --input "$tmp/chain_$n.g2o")
size=$(stat -c %s "$tmp/chain_$n.g2o")
echo "optimize_pose_graph: $n-node chain ($size B): peak ${g_large} kB, $(((g_large - g_small) * 1024 / n)) B per node," \
  "$(awk -v p="$g_large" -v s="$size" 'BEGIN { printf "%.1f", p * 1024 / s }')x the file"
