#!/usr/bin/env bash
# Learning curves beyond the paper's workspace, as reported in tools/bench/README.md:
# 4,000 rows of the simulated robot with bends up to 0.7 rad and a 200-row
# test set from another session of the same robot; the exact GP and the
# sparse GP (M = 1,024, the runtime's capacity, or N if fewer) against N,
# the sparse GP against M at N = 4,000, and the training time against N.
# One optimiser start each (--restarts 0), so the times compare like with
# like. Writes the plots to tools/bench/figures/ and the table to
# $BUILD_DIR/learning_curve_bench/.
#
#   bash tools/bench/run_learning_curve_bench.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
source tools/bench/bench_build.sh

bench_work learning_curve_bench base "" cdcr

"$cdcr" simulate --samples 4000 --seed 1 --workspace-theta-max 0.7 --out "$work_dir/train.csv" >/dev/null
"$cdcr" simulate --samples 200 --seed 1 --session 1 --workspace-theta-max 0.7 --out "$work_dir/test.csv" --json \
  >"$work_dir/test-simulate.json"
floor=$(noise_floor "$work_dir/test-simulate.json")
echo "noise floor of the test set: $floor (mm, deg)"
"$cdcr" learning-curve --data "$work_dir/train.csv" --test-data "$work_dir/test.csv" \
  --sizes 250,500,1000,2000,4000 --encodings bend-vector --models exact,sparse --inducing 1024 \
  --inducing-sizes 64,128,256,512,1024 --restarts 0 --noise-floor "$floor" \
  --plot-prefix tools/bench/figures/wide-workspace | tee "$work_dir/learning_curve.txt"
