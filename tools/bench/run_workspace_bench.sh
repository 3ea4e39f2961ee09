#!/usr/bin/env bash
# Plain `cdcr train` against the simulator's noise floor on three data sets,
# each with a test set from another data-collection session of the same
# robot (`--session 1`):
#   paper      the default workspace (bends up to 0.2 rad), 700 rows, 400 test rows;
#   low-noise  the same with the per-sample noise at a quarter (--noise-scale 0.25);
#   wide       bends up to 0.7 rad, 4,000 rows, 200 test rows.
# Each with the design geometry and with --calibrate. Then paper and wide
# again from the same robot built without geometric errors
# (`--no-geometric`: no length, radius or anchor-angle errors, no segment,
# base or platform mounts): the most any identification of the geometry could
# buy, were it perfect.
# "float32 max" is the largest difference between the image's float32 path
# (double accumulators, as on the M7 and the host) and the double-precision
# trainer on the held-out rows.
# The floor is the test set's measured pose against its noise-free pose
# (`cdcr simulate` reports it). On the wide data, scikit-learn's exact GP on
# the first 1,000 and 2,000 rows is timed in the same run, with the same
# number of optimiser starts as `cdcr train` (3) at 1,000 rows and one start
# at 2,000 (three would take most of an hour).
#
#   bash tools/bench/run_workspace_bench.sh [--skip-sklearn]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
source tools/bench/bench_build.sh

skip_sklearn=0
while [[ $# -gt 0 ]]; do
  case $1 in
    --skip-sklearn) skip_sklearn=1; shift ;;
    *) echo "run_workspace_bench: unknown argument $1" >&2; exit 2 ;;
  esac
done

bench_work workspace_bench "base sklearn" "-DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON" cdcr cdcr-bench-training

simulate_case() {  # name, training rows, test rows, simulate options...
  local name=$1 rows=$2 test_rows=$3
  shift 3
  "$cdcr" simulate --samples "$rows" --seed 1 "$@" --out "$work_dir/$name-train.csv" --json >"$work_dir/$name-simulate.json"
  "$cdcr" simulate --samples "$test_rows" --seed 1 --session 1 "$@" --out "$work_dir/$name-test.csv" --json \
    >"$work_dir/$name-test-simulate.json"
}

train_case() {  # data name, result name, cdcr train options...
  local name=$1 result=$2
  shift 2
  echo "$result: training..." >&2
  "$cdcr" train --data "$work_dir/$name-train.csv" --out "$work_dir/$result.img" --json "$@" >"$work_dir/$result-train.json"
  "$cdcr" eval --model "$work_dir/$result.img" --data "$work_dir/$name-test.csv" --json >"$work_dir/$result-eval.json"
}

simulate_case paper 700 400
simulate_case low-noise 700 400 --noise-scale 0.25
simulate_case wide 4000 200 --workspace-theta-max 0.7
simulate_case paper-exact-geometry 700 400 --no-geometric
simulate_case wide-exact-geometry 4000 200 --workspace-theta-max 0.7 --no-geometric
for name in paper low-noise wide; do
  train_case "$name" "$name"
  train_case "$name" "$name-calibrated" --calibrate
done
for name in paper-exact-geometry wide-exact-geometry; do
  train_case "$name" "$name"
done

if [[ $skip_sklearn == 0 ]]; then
  for rows in 1000 2000; do
    restarts=2
    [[ $rows == 2000 ]] && restarts=0
    echo "wide: scikit-learn's exact GP on $rows rows..." >&2
    "$build_dir/bin/cdcr-bench-training" --data "$work_dir/wide-train.csv" --samples "$rows" --restarts "$restarts" \
      --repetitions 1 --export "$work_dir/wide-xy-$rows.json" >"$work_dir/wide-cdcr-exact-$rows.json"
    /usr/bin/python3 tools/bench/sklearn_training_bench.py "$work_dir/wide-xy-$rows.json" --restarts "$restarts" \
      --repetitions 1 >"$work_dir/wide-sklearn-$rows.json"
  done
fi

/usr/bin/python3 - "$work_dir" "$skip_sklearn" <<'PYTHON'
import json
import os
import sys

work_dir, skip_sklearn = sys.argv[1], sys.argv[2] == "1"


def load(name):
    with open(os.path.join(work_dir, name)) as f:
        return json.load(f)


print("| data | rows | geometry | model | image bytes | M7 forward cycle | train s "
      "| test position mm (floor, ratio) | test orientation deg (floor, ratio) | float32 max mm |")
print("|---|---:|---|---|---:|---:|---:|---:|---:|---:|")
cases = [(name, ((name, "design"), (f"{name}-calibrated", "calibrated"))) for name in ("paper", "low-noise", "wide")]
cases += [(f"{name}-exact-geometry", ((f"{name}-exact-geometry", "design; robot without geometric errors"),))
          for name in ("paper", "wide")]
for name, results in cases:
    floor = load(f"{name}-test-simulate.json")["noise_floor"]
    for result, geometry in results:
        trained = load(f"{result}-train.json")
        evaluated = load(f"{result}-eval.json")
        model = trained["model"]
        position = evaluated["compensated"]["position_mm"]
        orientation = evaluated["compensated"]["orientation_deg"]
        print(f"| {name} | {trained['fitted_rows']} | {geometry} | {model['kind']}, {model['points']} points "
              f"| {trained['image']['bytes']} | {model['forward_cycle_instructions_m7']} | {trained['seconds']:.1f} "
              f"| {position:.3f} ({floor['position_mm']:.3f}, {position / floor['position_mm']:.3f}x) "
              f"| {orientation:.4f} ({floor['orientation_deg']:.4f}, {orientation / floor['orientation_deg']:.3f}x) "
              f"| {trained['float32_fidelity']['double accumulators']['max_position_mm']:.4f} |")

if not skip_sklearn:
    wide_seconds = load("wide-train.json")["seconds"]
    print()
    print("| wide data, exact GP | rows | starts | s | log marginal likelihood |")
    print("|---|---:|---:|---:|---:|")
    for rows in (1000, 2000):
        ours = load(f"wide-cdcr-exact-{rows}.json")
        theirs = load(f"wide-sklearn-{rows}.json")
        for label, r in (("cdcr (C++)", ours), ("scikit-learn", theirs)):
            print(f"| {label} | {rows} | {r['starts']} | {r['median_seconds']:.1f} | {r['log_marginal_likelihood']:.2f} |")
    sklearn_1000 = load("wide-sklearn-1000.json")["median_seconds"]
    print(f"\nplain cdcr train on all 4,000 rows: {wide_seconds:.1f} s; scikit-learn on 1,000 rows, same starts: "
          f"{sklearn_1000:.1f} s ({sklearn_1000 / wide_seconds:.1f}x)")
PYTHON
