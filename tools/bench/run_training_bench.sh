#!/usr/bin/env bash
# The GP hyperparameter search of `cdcr train` against scikit-learn fitting the
# same data in the same run: 700 samples of the simulated robot, 8 inputs
# (bend-vector encoding), 6 outputs, ARD squared-exponential kernel with
# learned noise, the same bounds, one optimiser start each from the same
# point (unit length scales and signal variance, noise 0.1). Reports the
# median wall time of each, their ratio, the log marginal likelihood each
# reached on the identical normalised data, the evaluations each took and
# the time per evaluation (the stopping rules differ: LBFGSpp's relative
# gradient 1e-5 against scipy's projected gradient 1e-5), and the floor of
# cdcr's search: its evaluations' flops at the rate this machine reaches on
# a dense product.
#
#   bash tools/bench/run_training_bench.sh [--restarts R] [--repetitions K]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
source tools/bench/bench_build.sh

restarts=0
repetitions=3
while [[ $# -gt 0 ]]; do
  case $1 in
    --restarts) restarts=$2; shift 2 ;;
    --repetitions) repetitions=$2; shift 2 ;;
    *) echo "run_training_bench: unknown argument $1" >&2; exit 2 ;;
  esac
done

bench_work training_bench --show-build "base sklearn" "-DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON" cdcr cdcr-bench-training

# Both sides' BLAS on one thread per call: the trainer's default (its
# search uses the cores by running starts side by side), and scikit-learn's
# faster setting on a busy machine (numpy's OpenBLAS waits in every call
# for a second thread that other processes may hold).
export OPENBLAS_NUM_THREADS=1
"$build_dir/bin/cdcr" simulate --samples 700 --seed 11 --out "$work_dir/data.csv" >/dev/null
echo "cdcr (C++, Eigen + OpenBLAS + LBFGSpp): fitting..."
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
print("| trainer | median s | log marginal likelihood | evaluations | ms per evaluation |")
print("|---|---:|---:|---:|---:|")
for name, r in (("cdcr train (C++)", ours), ("scikit-learn", theirs)):
    per = 1e3 * r["median_seconds"] / r["likelihood_evaluations"]
    print(f"| {name} | {r['median_seconds']:.2f} | {r['log_marginal_likelihood']:.3f} | "
          f"{r['likelihood_evaluations']} | {per:.1f} |")
per_ratio = (theirs["median_seconds"] / theirs["likelihood_evaluations"]) / (
    ours["median_seconds"] / ours["likelihood_evaluations"])
print(f"\nscikit-learn's numpy/scipy BLAS: {theirs['blas']}")
print(f"\nspeed-up: {ratio:.1f}x overall, {per_ratio:.1f}x per evaluation; LML difference (cdcr - scikit-learn): "
      f"{ours['log_marginal_likelihood'] - theirs['log_marginal_likelihood']:+.3f}")
print(f"floor of cdcr's search: {ours['likelihood_evaluations']} evaluations x "
      f"{ours['flops_per_evaluation'] / 1e6:.0f} Mflop at {ours['achieved_gflops']:.1f} GFLOP/s "
      f"(an N x N BLAS product on this machine) = {ours['floor_seconds']:.2f} s; measured {ours['median_seconds']:.2f} s")
PYTHON
