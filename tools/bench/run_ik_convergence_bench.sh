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

build_dir=${BUILD_DIR:-build}
work=$build_dir/ik_bench

cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON \
  --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr cdcr-bench-ik >/dev/null

mkdir -p "$work"
"$build_dir/bin/cdcr" simulate --samples 700 --seed 1 --out "$work/train.csv.new" >/dev/null
if [[ ! -f $work/model.img ]] || ! cmp -s "$work/train.csv.new" "$work/train.csv"; then
  mv "$work/train.csv.new" "$work/train.csv"
  echo "Training the 700-point image (log: $work/train.log)..."
  "$build_dir/bin/cdcr" train --data "$work/train.csv" --out "$work/model.img.new" >"$work/train.log" 2>&1
  mv "$work/model.img.new" "$work/model.img"
else
  rm -f "$work/train.csv.new"
fi
"$build_dir/bin/cdcr-bench-ik" --image "$work/model.img" "$@"
