#!/usr/bin/env bash
# A smaller closed-loop hysteresis bench (tools/bench/
# run_closed_loop_hysteresis_bench.sh) with a margin: on the simulator's
# robot with its friction, 300 training rows of a motion sequence, one image
# trained with the hysteresis model and one joints-only; each runs
# `cdcr-runtime --sim --hysteresis` (homing, HOMING, the six targets each from
# two sides; then the streamed circle). The hysteresis-aware runtime must
# reach the targets within 2.5 mm and follow the circle within 1.5 mm on
# average, and each below half the joints-only runtime's error (the full
# bench: 0.24x and 0.07x).
#
#   closed_loop_hysteresis_test.sh CDCR CDCR_RUNTIME WORK_DIR
set -euo pipefail
cdcr=$1 runtime=$2 work_dir=$3
mkdir -p "$work_dir"

"$cdcr" simulate --hysteresis --samples 300 --out "$work_dir/train.csv" >/dev/null
"$cdcr" train --data "$work_dir/train.csv" --out "$work_dir/hysteresis.img" >/dev/null
"$cdcr" train --no-hysteresis --data "$work_dir/train.csv" --out "$work_dir/joints.img" >/dev/null

mean_of() {
  sed -n "s/.*$2.*mean \([0-9.]*\) mm.*/\1/p" "$1" | head -n 1
}

failed=0
# check MEASURE AWARE_MM JOINTS_MM BOUND_MM
check() {
  local verdict
  verdict=$(awk -v a="$2" -v j="$3" -v bound="$4" \
    'BEGIN { if (a == "" || j == "") print "no figure"; else if (a + 0 < bound + 0 && a + 0 < 0.5 * j) print "ok"; else print "FAILED" }')
  echo "$1: hysteresis-aware ${2:-?} mm, joints-only ${3:-?} mm (needs < $4 mm and < 0.5x): $verdict"
  [[ $verdict == ok ]] || failed=1
}

for image in hysteresis joints; do
  "$runtime" --image "$work_dir/$image.img" --sim --hysteresis --seconds 3 >"$work_dir/$image.targets.txt"
  "$runtime" --image "$work_dir/$image.img" --sim --hysteresis --circle >"$work_dir/$image.circle.txt"
done
check "six targets from two sides" "$(mean_of "$work_dir/hysteresis.targets.txt" "tip vs target after")" \
  "$(mean_of "$work_dir/joints.targets.txt" "tip vs target after")" 2.5
check "streamed circle" "$(mean_of "$work_dir/hysteresis.circle.txt" "tip vs streamed target")" \
  "$(mean_of "$work_dir/joints.circle.txt" "tip vs streamed target")" 1.5
exit "$failed"
