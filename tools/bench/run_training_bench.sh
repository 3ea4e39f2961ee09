#!/usr/bin/env bash
# The GP hyperparameter search of `cdcr train` against scikit-learn fitting the
# same data in the same run: 700 samples of the simulated robot, 8 inputs
# (bend-vector encoding), 6 outputs, ARD squared-exponential kernel with
# learned noise, the same bounds and the same number of optimiser starts.
# Reports the median wall time of each, their ratio, and the log marginal
# likelihood each reached on the identical normalised data.
#
#   bash tools/bench/run_training_bench.sh [--restarts R] [--repetitions K]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

restarts=2
repetitions=3
while [[ $# -gt 0 ]]; do
  case $1 in
    --restarts) restarts=$2; shift 2 ;;
    --repetitions) repetitions=$2; shift 2 ;;
    *) echo "run_training_bench: unknown argument $1" >&2; exit 2 ;;
  esac
done

build_dir=${BUILD_DIR:-build}
work_dir=$build_dir/training_bench
bash tools/install-deps.sh base sklearn
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON \
  --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr cdcr-bench-training
mkdir -p "$work_dir"

"$build_dir/bin/cdcr" simulate --samples 700 --seed 11 --out "$work_dir/data.csv" >/dev/null
echo "cdcr (C++, Eigen + LBFGSpp): fitting..."
"$build_dir/bin/cdcr-bench-training" --data "$work_dir/data.csv" --samples 700 --restarts "$restarts" \
  --repetitions "$repetitions" --export "$work_dir/xy.json" >"$work_dir/cdcr.json"
echo "scikit-learn: fitting..."
/usr/bin/python3 tools/bench/sklearn_training_bench.py "$work_dir/xy.json" --restarts "$restarts" \
  --repetitions "$repetitions" >"$work_dir/sklearn.json"

/usr/bin/python3 - "$work_dir/cdcr.json" "$work_dir/sklearn.json" "$(nproc)" <<'PYTHON'
import json
import sys

ours, theirs = (json.load(open(path)) for path in sys.argv[1:3])
cpus = sys.argv[3]
ratio = theirs["median_seconds"] / ours["median_seconds"]
print(f"\n{ours['samples']} samples x {ours['inputs']} inputs, {ours['outputs']} outputs, "
      f"{ours['starts']} optimiser starts each, median of {len(ours['seconds'])} runs, {cpus} CPUs\n")
print("| trainer | median s | log marginal likelihood |")
print("|---|---:|---:|")
print(f"| cdcr train (C++) | {ours['median_seconds']:.2f} | {ours['log_marginal_likelihood']:.3f} |")
print(f"| scikit-learn {''} | {theirs['median_seconds']:.2f} | {theirs['log_marginal_likelihood']:.3f} |")
print(f"\nspeed-up: {ratio:.1f}x; LML difference (cdcr - scikit-learn): "
      f"{ours['log_marginal_likelihood'] - theirs['log_marginal_likelihood']:+.3f}")
PYTHON
