#!/usr/bin/env bash
# Cable hysteresis on a robot other than the simulator's (issue 25,
# acceptance 2), as reported in tools/bench/README.md: tools/bench/independent_robot.py
# records a training session (700 rows) and a test session (200 rows) of a
# four-segment robot with Bouc-Wen cable friction, then
#   - the joints-only model: `cdcr train` on the training rows without their
#     time column (independent samples, as the paper) and `cdcr eval` on the
#     test rows without it;
#   - the hysteresis-aware model: the same on the motion sequences, with t_s,
#     where this build reads a time column (otherwise it says so and goes on);
#   - two references: the joints-only model on the same robot without
#     friction, and on the true effective cable lengths (what a model that
#     knew the friction exactly would reach).
# Every error is printed against the test session's noise floor. Writes to
# $BUILD_DIR/hysteresis_bench/.
#
#   bash tools/bench/run_hysteresis_bench.sh [--seed S]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
source tools/bench/bench_build.sh

seed=$(seed_option 7 "$@")
bench_work hysteresis_bench "base sklearn" "" cdcr
python=/usr/bin/python3
# The robot's nominal geometry, as independent_robot.py states it.
geometry=(--segments 4 --length 110 --radius 60)

# The same rows without the time column: independent samples.
drop_time() {
  awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } { $1 = ""; print substr($0, 2) }' "$1" >"$2"
}

# train_and_eval NAME TRAIN_CSV TEST_CSV: prints "position_mm orientation_deg"
# of the compensated test rows, or returns 1 with cdcr's error in NAME.err.
train_and_eval() {
  local name=$1 train=$2 test=$3
  "$cdcr" train --data "$train" --out "$work_dir/$name.img" "${geometry[@]}" >"$work_dir/$name.train.txt" \
    2>"$work_dir/$name.err" || return 1
  "$cdcr" eval --model "$work_dir/$name.img" --data "$test" --json >"$work_dir/$name.eval.json" \
    2>"$work_dir/$name.err" || return 1
  "$python" -c 'import json, sys; c = json.load(open(sys.argv[1]))["compensated"]; print(c["position_mm"], c["orientation_deg"])' \
    "$work_dir/$name.eval.json"
}

echo "== the independent robot (seed $seed) =="
"$python" tools/bench/independent_robot.py --seed "$seed" --out-dir "$work_dir/hysteresis" --effective \
  --report "$work_dir/robot.json" | tee "$work_dir/robot.txt"
"$python" tools/bench/independent_robot.py --seed "$seed" --out-dir "$work_dir/no_friction" --no-hysteresis \
  --report "$work_dir/no_friction.json" >/dev/null
for dir in hysteresis no_friction; do
  for session in 0 1; do
    drop_time "$work_dir/$dir/session$session.csv" "$work_dir/$dir/joints$session.csv"
  done
done
for session in 0 1; do
  drop_time "$work_dir/hysteresis/session$session.effective.csv" "$work_dir/hysteresis/effective$session.csv"
done

read -r floor_mm floor_deg nominal_mm nominal_deg < <("$python" -c '
import json, sys
s = json.load(open(sys.argv[1]))["sessions"][1]
print(s["noise_floor"]["position_mm"], s["noise_floor"]["orientation_deg"],
      s["nominal_error"]["position_mm"], s["nominal_error"]["orientation_deg"])' "$work_dir/robot.json")

# row LABEL POSITION ORIENTATION
row() {
  awk -v label="$1" -v mm="$2" -v deg="$3" -v fmm="$floor_mm" -v fdeg="$floor_deg" \
    'BEGIN { printf "  %-38s %8.3f mm %8.4f deg   %6.2fx %6.2fx the floor\n", label, mm, deg, mm / fmm, deg / fdeg }'
}

echo
echo "== test session (200 rows) =="
row "noise floor" "$floor_mm" "$floor_deg"
row "nominal model" "$nominal_mm" "$nominal_deg"
if result=$(train_and_eval joints_only "$work_dir/hysteresis/joints0.csv" "$work_dir/hysteresis/joints1.csv"); then
  read -r joints_mm joints_deg <<<"$result"
  row "joints-only model" "$joints_mm" "$joints_deg"
else
  echo "  joints-only model: $(head -n 1 "$work_dir/joints_only.err")"
  exit 1
fi
if result=$(train_and_eval hysteresis_aware "$work_dir/hysteresis/session0.csv" "$work_dir/hysteresis/session1.csv"); then
  read -r aware_mm aware_deg <<<"$result"
  row "hysteresis-aware model (with t_s)" "$aware_mm" "$aware_deg"
  awk -v a="$aware_mm" -v j="$joints_mm" 'BEGIN { printf "  hysteresis-aware / joints-only: %.2f (position)\n", a / j }'
else
  echo "  hysteresis-aware model: not measured, this build does not train on a time column:"
  echo "    $(head -n 1 "$work_dir/hysteresis_aware.err")"
fi
if result=$(train_and_eval no_friction "$work_dir/no_friction/joints0.csv" "$work_dir/no_friction/joints1.csv"); then
  read -r free_mm free_deg <<<"$result"
  row "joints-only, same robot without friction" "$free_mm" "$free_deg"
fi
if result=$(train_and_eval effective "$work_dir/hysteresis/effective0.csv" "$work_dir/hysteresis/effective1.csv"); then
  read -r known_mm known_deg <<<"$result"
  row "joints-only on the true effective lengths" "$known_mm" "$known_deg"
fi
echo
echo "models, reports and data in $work_dir"
