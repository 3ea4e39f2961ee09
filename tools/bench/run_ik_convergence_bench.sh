#!/usr/bin/env bash
# Builds cdcr and cdcr-bench-ik in Release, trains the demo's 700-point image
# on the simulated robot (700 samples, seed 1, as tools/demo.sh steps 4-5)
# and prints the IK convergence counts over the fixed target sets and the
# single pose target to the start of the demo's streamed circle.
#
#   bash tools/bench/run_ik_convergence_bench.sh [cdcr-bench-ik flags...]
#   BUILD_DIR=build-bench bash tools/bench/run_ik_convergence_bench.sh --targets 5000 --seed 3
#
# The image and the training data stay in $BUILD_DIR/ik_bench/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

source tools/bench/bench_build.sh

bench_work ik_bench base "-DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON" cdcr cdcr-bench-ik
# Training takes seconds; keep an image whose data set has not changed.
"$cdcr" simulate --samples 700 --seed 1 --out "$work_dir/train.csv.new" >/dev/null
if [[ ! -f $work_dir/model.img ]] || ! cmp -s "$work_dir/train.csv.new" "$work_dir/train.csv"; then
  mv "$work_dir/train.csv.new" "$work_dir/train.csv"
  echo "Training the 700-point image (log: $work_dir/train.log)..."
  "$cdcr" train --data "$work_dir/train.csv" --out "$work_dir/model.img.new" >"$work_dir/train.log" 2>&1
  mv "$work_dir/model.img.new" "$work_dir/model.img"
else
  rm -f "$work_dir/train.csv.new"
fi
"$build_dir/bin/cdcr-bench-ik" --image "$work_dir/model.img" "$@"
