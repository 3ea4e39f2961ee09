#!/usr/bin/env bash
# The paper's protocol on the simulated robot, as reported in tools/bench/README.md:
# 750 samples, 50 held out, learning curve at N = 100..700 for both input
# encodings, then shared against per-output hyperparameters. Writes the
# figures to tools/bench/figures/ and the tables to $BUILD_DIR/accuracy_bench/.
#
#   bash tools/bench/run_accuracy_bench.sh [--seed S]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

seed=1
if [[ ${1:-} == --seed ]]; then seed=$2; fi

build_dir=${BUILD_DIR:-build}
work_dir=$build_dir/accuracy_bench
bash tools/install-deps.sh base
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr >/dev/null
mkdir -p "$work_dir"
cdcr=$build_dir/bin/cdcr

"$cdcr" simulate --samples 750 --seed "$seed" --out "$work_dir/data.csv" --json >"$work_dir/simulate.json"
floor=$(/usr/bin/python3 - "$work_dir/simulate.json" <<'PYTHON'
import json
import sys

floor = json.load(open(sys.argv[1]))["noise_floor"]
print("{},{}".format(floor["position_mm"], floor["orientation_deg"]))
PYTHON
)
echo "simulated robot (seed $seed): $(cat "$work_dir/simulate.json")"

echo
echo "== learning curve, both encodings, shared hyperparameters =="
"$cdcr" learning-curve --data "$work_dir/data.csv" --noise-floor "$floor" \
  --plot-prefix tools/bench/figures/learning-curve | tee "$work_dir/learning_curve.txt"

echo
echo "== shared vs per-output hyperparameters (bend-vector encoding) =="
"$cdcr" learning-curve --data "$work_dir/data.csv" --sizes 300,700 --encodings bend-vector --sharing per-output \
  --plot-prefix "$work_dir/per-output" | tee "$work_dir/per_output.txt"
