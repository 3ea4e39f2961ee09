#!/usr/bin/env bash
# Robots of three cables a segment at 120 degrees, through the chain a user
# runs: the simulator (the demo's robot, seed 1: simulate, train, eval, the
# closed loop with targets and the streamed circle) and the independent
# robot (tools/bench/independent_robot.py --cables 3, seeds 7 and 8:
# consistent commands with Bouc-Wen friction, a motion sequence).
#
#   bash tools/bench/run_three_cable_bench.sh [--cdcr build/bin/cdcr] [--runtime build/bin/cdcr-runtime]
#
# Prints each run's figures; the figures in tools/bench/README.md ("Three
# cables a segment") come from it. Needs numpy for the independent robot.
set -euo pipefail

cdcr=build/bin/cdcr
runtime=build/bin/cdcr-runtime
while [[ $# -gt 0 ]]; do
  case $1 in
    --cdcr) cdcr=$2; shift 2 ;;
    --runtime) runtime=$2; shift 2 ;;
    *) echo "usage: $0 [--cdcr PATH] [--runtime PATH]" >&2; exit 2 ;;
  esac
done
for tool in "$cdcr" "$runtime"; do
  [[ -x $tool ]] || { echo "$0: $tool not found (cmake --build build)" >&2; exit 2; }
done
python=/usr/bin/python3
"$python" -c 'import numpy' 2>/dev/null || { echo "$0: numpy not found (apt-get install python3-numpy)" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
here=$(cd "$(dirname "$0")" && pwd)

echo "== simulator, three cables a segment, seed 1 (the demo's robot)"
"$cdcr" simulate --cables-per-segment 3 --samples 700 --seed 1 --out "$work/sim_train.csv" >/dev/null
"$cdcr" simulate --cables-per-segment 3 --samples 200 --seed 1 --session 1 --out "$work/sim_test.csv" |
  grep "noise floor"
"$cdcr" train --data "$work/sim_train.csv" --out "$work/sim.img" >/dev/null
"$cdcr" eval --model "$work/sim.img" --data "$work/sim_test.csv"
"$runtime" --image "$work/sim.img" --sim --rate 1000 --seconds 3 | tail -3
"$runtime" --image "$work/sim.img" --sim --circle --circle-radius 40 --circle-speed 50 | tail -3

for seed in 7 8; do
  echo "== independent robot, three cables a segment, seed $seed"
  "$python" "$here/independent_robot.py" --seed "$seed" --cables 3 --out-dir "$work/ir$seed" |
    grep -A1 "session 1" | grep "noise floor"
  "$cdcr" train --data "$work/ir$seed/session0.csv" --length 110 --radius 60 --out "$work/ir$seed.img" |
    grep -E "chosen|per_cable K|all_cables K" | tail -1
  "$cdcr" eval --model "$work/ir$seed.img" --data "$work/ir$seed/session1.csv"
done
