#!/usr/bin/env bash
# The paper's protocol on the simulated robot, as reported in tools/bench/README.md:
# 750 samples, 50 held out, learning curve at N = 100..700 for both input
# encodings, then shared against per-output hyperparameters. Writes the
# figures to tools/bench/figures/ and the tables to $BUILD_DIR/accuracy_bench/.
#
#   bash tools/bench/run_accuracy_bench.sh [--seed S]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
source tools/bench/bench_build.sh

seed=$(seed_option 1 "$@")
bench_work accuracy_bench base "" cdcr

"$cdcr" simulate --samples 750 --seed "$seed" --out "$work_dir/data.csv" --json >"$work_dir/simulate.json"
floor=$(noise_floor "$work_dir/simulate.json")
echo "simulated robot (seed $seed): $(cat "$work_dir/simulate.json")"

echo
echo "== learning curve, both encodings, shared hyperparameters =="
"$cdcr" learning-curve --data "$work_dir/data.csv" --noise-floor "$floor" \
  --plot-prefix tools/bench/figures/learning-curve | tee "$work_dir/learning_curve.txt"

echo
echo "== shared vs per-output hyperparameters (bend-vector encoding) =="
"$cdcr" learning-curve --data "$work_dir/data.csv" --sizes 300,700 --encodings bend-vector --sharing per-output \
  --plot-prefix "$work_dir/per-output" | tee "$work_dir/per_output.txt"
