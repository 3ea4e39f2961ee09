#!/usr/bin/env bash
# Builds cdcr and the runtime benchmark in Release, trains a 700-point image
# on the simulated robot (the demo's data: 700 samples, seed 1, 50 held out
# to validate, the image fitted on all 700)
# and prints the per-cycle compute-time table of cdcr-bench-runtime.
#
#   bash tools/bench/run_runtime_bench.sh [cdcr-bench-runtime flags...]
#   BUILD_DIR=build-bench bash tools/bench/run_runtime_bench.sh --repetitions 9
#
# The image and the training data stay in $BUILD_DIR/runtime_bench/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

build_dir=${BUILD_DIR:-build}
work=$build_dir/runtime_bench

bash tools/install-deps.sh base
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON \
  --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr cdcr-bench-runtime >/dev/null

mkdir -p "$work"
# Training takes seconds; keep a model whose data set has not changed.
"$build_dir/bin/cdcr" simulate --samples 700 --seed 1 --out "$work/train.csv.new" >/dev/null
if [[ ! -f $work/model.img ]] || ! cmp -s "$work/train.csv.new" "$work/train.csv"; then
  mv "$work/train.csv.new" "$work/train.csv"
  echo "Training the 700-point image (log: $work/train.log)..."
  {
    "$build_dir/bin/cdcr" train --data "$work/train.csv" --out "$work/model.img.new" &&
      mv "$work/model.img.new" "$work/model.img"
  } >"$work/train.log" 2>&1 || {
    tail -n 20 "$work/train.log" >&2
    exit 1
  }
fi
rm -f "$work/train.csv.new"

cpu_model=$(sed -n 's/^model name[[:space:]]*:[[:space:]]*//p' /proc/cpuinfo | head -n 1)
revision=$(git describe --always --dirty 2>/dev/null || echo unknown)
echo "Runtime cycle benchmark, $(date -u +%F), revision $revision"
echo "CPU: ${cpu_model:-unknown}, nproc $(nproc); Release build, host steady_clock around Runtime::run_cycle()"
"$build_dir/bin/cdcr-bench-runtime" --image "$work/model.img" "$@"
