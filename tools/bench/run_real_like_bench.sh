#!/usr/bin/env bash
# What makes the real robot's recordings hard, on the independent robot's
# real-like preset (tools/bench/independent_robot.py --preset lab-1seg: one
# segment, L = 64 mm, r = 8 mm, four cables, tendon statics with capstan
# friction), as reported in tools/bench/README.md:
#   - babbling, 4,022 rows in order (each cable within +-13 mm of straight,
#     independently), per seed: the share of rows beyond pi/2 by the
#     constant-curvature map, the pair sums' spread, the nominal model, and
#     scikit-learn's GP (ARD SE + white noise) on the first 80 % (at most
#     1,500 rows, evenly spaced) given all four cables and given only
#     l3 - l1, l2 - l4, on the last 20 %; the robot's noise floor;
#   - repeatability, 17 commands (straight, 6 and 12 mm of antagonistic pull
#     in 8 directions) each reached twice from each other one, 544 rows in
#     order, per seed: the same command from the same previous one, a
#     joints-only GP and a GP also given the sign of each cable's last move.
# With --cdcr, the babbling runs also train and evaluate the project's model
# (cdcr train on the same rows as the GP, and on the first 80 % as a
# sequence; cdcr eval on the last 20 %), and the repeatability runs the
# project's sequence model with and without the history inputs. With
# --kernels, the babbling runs also fit Matern kernels and GPs given the sign
# of each cable's last move (real_like_bench.py --kernels).
# Needs numpy and scikit-learn (the sklearn group); builds nothing. Writes to
# $BUILD_DIR/real_like_bench/.
#
#   bash tools/bench/run_real_like_bench.sh [--seeds "1 2"] [--rows 4022] [--cdcr build/bin/cdcr] [--kernels]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

seeds="1 2"
rows=4022
cdcr_option=()
kernels_option=()
while [ $# -gt 0 ]; do
  case $1 in
    --cdcr) cdcr_option=(--cdcr "$2"); shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --kernels) kernels_option=(--kernels); shift ;;
    --rows) rows=$2; shift 2 ;;
    *) echo "run_real_like_bench.sh: error: unknown option '$1'" >&2; exit 2 ;;
  esac
done
python=/usr/bin/python3
"$python" -c 'import numpy, sklearn' 2>/dev/null || bash tools/install-deps.sh sklearn
work_dir=${BUILD_DIR:-build}/real_like_bench
mkdir -p "$work_dir"

for seed in $seeds; do
  echo "== babbling, seed $seed, $rows rows =="
  nice -n 19 "$python" tools/bench/independent_robot.py --preset lab-1seg --collection babbling --seed "$seed" \
    --rows "$rows,1" --out-dir "$work_dir/babbling$seed" --report "$work_dir/babbling$seed.json" >/dev/null
  nice -n 19 "$python" tools/bench/real_like_bench.py babbling "$work_dir/babbling$seed/session0.csv" \
    --report "$work_dir/babbling$seed.json" "${cdcr_option[@]}" "${kernels_option[@]}" | tee "$work_dir/babbling$seed.txt"
  echo "== repeatability, seed $seed =="
  nice -n 19 "$python" tools/bench/independent_robot.py --preset lab-1seg --collection repeatability \
    --seed "$seed" --rows 1,1 --out-dir "$work_dir/repeatability$seed" \
    --report "$work_dir/repeatability$seed.json" >/dev/null
  nice -n 19 "$python" tools/bench/real_like_bench.py repeatability "$work_dir/repeatability$seed/session0.csv" \
    --report "$work_dir/repeatability$seed.json" "${cdcr_option[@]}" | tee "$work_dir/repeatability$seed.txt"
done
