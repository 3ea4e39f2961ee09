#!/usr/bin/env bash
# The payload model on two robots (issue 25, "the payload's load"): the
# independent robot of tools/bench/independent_robot.py (its own kinematics,
# its own sag under a tip payload, no cable friction) and the simulator, each
# with a tip payload uniform in 0-1 kg per sample: 700 training samples
# (session 0) and 200 test samples (session 1), `cdcr train` (the payload
# column is a GP input) and `cdcr eval`. Prints the compensated test error
# against the test session's noise floor (the measured poses against the
# repeatable ones, as each robot defines it). Writes to
# $BUILD_DIR/payload_bench/. A reference row: the independent robot without
# payload. Then, on the same rows, the payload model with the segments'
# compliance identified (cdcr-bench-compliance: every candidate structure,
# the one the GP's likelihood chooses, and the baseline again, each with the
# same search as `cdcr train`).
#
#   bash tools/bench/run_payload_bench.sh [--seed S]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
source tools/bench/bench_build.sh

seed=$(seed_option 7 "$@")
bench_work payload_bench base "-DCDCR_BUILD_BENCHMARKS=ON" cdcr cdcr-bench-compliance
python=/usr/bin/python3
payload_range=0,1

# report NAME TRAIN_CSV TEST_CSV FLOOR_MM FLOOR_DEG [GEOMETRY...]: trains,
# evaluates and prints the compensated error against the floor.
report() {
  local name=$1 train=$2 test=$3 floor_mm=$4 floor_deg=$5
  local file=$work_dir/${name//[^a-z]/_}
  shift 5
  "$cdcr" train --data "$train" --out "$file.img" "$@" >"$file.train.txt"
  "$cdcr" eval --model "$file.img" --data "$test" --json >"$file.eval.json"
  "$python" - "$file.eval.json" "$name" "$floor_mm" "$floor_deg" <<'PYTHON'
import json
import sys

report = json.load(open(sys.argv[1]))
compensated, initial = report["compensated"], report.get("initial", {})
floor_mm, floor_deg = float(sys.argv[3]), float(sys.argv[4])
print("  {:<20} noise floor  {:7.3f} mm {:7.4f} deg".format(sys.argv[2], floor_mm, floor_deg))
if initial:
    print("  {:<20} nominal      {:7.3f} mm {:7.4f} deg".format("", initial["position_mm"], initial["orientation_deg"]))
print("  {:<20} compensated  {:7.3f} mm {:7.4f} deg   {:.2f}x {:.2f}x the floor".format(
    "", compensated["position_mm"], compensated["orientation_deg"],
    compensated["position_mm"] / floor_mm, compensated["orientation_deg"] / floor_deg))
PYTHON
}

echo "== the independent robot (seed $seed), payload $payload_range kg =="
"$python" tools/bench/independent_robot.py --seed "$seed" --out-dir "$work_dir/independent" \
  --payload-range "$payload_range" --report "$work_dir/independent.json" | tee "$work_dir/independent.txt"
read -r floor_mm floor_deg < <("$python" -c '
import json, sys
s = json.load(open(sys.argv[1]))["sessions"][1]
print(s["noise_floor"]["position_mm"], s["noise_floor"]["orientation_deg"])' "$work_dir/independent.json")
# The robot's nominal geometry, as independent_robot.py states it.
report independent "$work_dir/independent/session0.csv" "$work_dir/independent/session1.csv" "$floor_mm" "$floor_deg" \
  --segments 4 --length 110 --radius 60

echo "  -- with the segments' compliance identified --"
"$build_dir/bin/cdcr-bench-compliance" --train "$work_dir/independent/session0.csv" \
  --test "$work_dir/independent/session1.csv" --floor-mm "$floor_mm" --floor-deg "$floor_deg" \
  --segments 4 --length 110 --radius 60 | tee "$work_dir/independent.compliance.txt"

# A reference: the same robot and configurations without payload (payload
# 0 kg, its column dropped): the part of the gap the payload does not cause.
"$python" tools/bench/independent_robot.py --seed "$seed" --out-dir "$work_dir/unloaded" --payload-range 0,0 \
  --report "$work_dir/unloaded.json" >/dev/null
for session in 0 1; do
  awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } { $17 = ""; sub(/,,/, ","); print }' \
    "$work_dir/unloaded/session$session.csv" >"$work_dir/unloaded/no_payload$session.csv"
done
read -r floor_mm floor_deg < <("$python" -c '
import json, sys
s = json.load(open(sys.argv[1]))["sessions"][1]
print(s["noise_floor"]["position_mm"], s["noise_floor"]["orientation_deg"])' "$work_dir/unloaded.json")
report "(without payload)" "$work_dir/unloaded/no_payload0.csv" "$work_dir/unloaded/no_payload1.csv" \
  "$floor_mm" "$floor_deg" --segments 4 --length 110 --radius 60

echo
echo "== the simulator (seed $seed), payload $payload_range kg =="
"$cdcr" simulate --samples 700 --seed "$seed" --payload-range "$payload_range" \
  --out "$work_dir/simulator0.csv" --json >"$work_dir/simulator0.json"
"$cdcr" simulate --samples 200 --seed "$seed" --session 1 --payload-range "$payload_range" \
  --out "$work_dir/simulator1.csv" --json >"$work_dir/simulator1.json"
IFS=, read -r floor_mm floor_deg < <(noise_floor "$work_dir/simulator1.json")
report simulator "$work_dir/simulator0.csv" "$work_dir/simulator1.csv" "$floor_mm" "$floor_deg"
echo "  -- with the segments' compliance identified --"
"$build_dir/bin/cdcr-bench-compliance" --train "$work_dir/simulator0.csv" --test "$work_dir/simulator1.csv" \
  --floor-mm "$floor_mm" --floor-deg "$floor_deg" | tee "$work_dir/simulator.compliance.txt"
echo
echo "models, reports and data in $work_dir"
