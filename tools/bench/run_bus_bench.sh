#!/usr/bin/env bash
# The CAN bus budget and the bus in time, as reported in tools/bench/README.md
# ("The bus in time"): `cdcr bus` for the paper's robot at 1 kHz (estimating,
# streaming) and the configurations that fit, classical, CAN FD and with the
# drives on a second bus; then the demo's streamed circle on timed buses
# (`cdcr-runtime --sim --bitrate`) with the demo's model (700 samples of the
# simulated robot, seed 1), where it fits: a classical 1 Mbit/s bus at
# 250 Hz, and at 1 kHz one FD bus (data at 5 Mbit/s) and two (2 Mbit/s).
#
#   bash tools/bench/run_bus_bench.sh [--cdcr build/bin/cdcr] [--runtime build/bin/cdcr-runtime]
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
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

budget() {
  echo "\$ cdcr bus $*"
  "$cdcr" bus "$@" | tail -n 1 || true
}
budget
budget --streaming
budget --streaming --rate 250 --uncertainty-every 5
budget --segments 2 --rate 500 --pose-every 2 --uncertainty-every 10
budget --streaming --drives-bus
budget --streaming --can-format fd
budget --streaming --can-format fd-brs --data-bitrate 5000000
budget --streaming --can-format fd-brs --data-bitrate 2000000 --drives-bus
budget --can-format fd-brs --data-bitrate 5000000
budget --drives-bus

"$cdcr" simulate --samples 700 --seed 1 --out "$work/train.csv" >/dev/null
"$cdcr" train --data "$work/train.csv" --out "$work/model.img" >/dev/null
for options in "--rate 250 --uncertainty-every 5" "--rate 250 --uncertainty-every 5 --pose-every 2"; do
  echo "\$ cdcr-runtime --sim --circle --bitrate 1000000 $options"
  # shellcheck disable=SC2086
  "$runtime" --image "$work/model.img" --sim --circle --bitrate 1000000 $options | sed -n '/^tip vs/,$p'
done
for options in "--can-format fd-brs --data-bitrate 5000000" "--can-format fd-brs --data-bitrate 2000000 --drives-bus"; do
  echo "\$ cdcr-runtime --sim --circle --bitrate 1000000 $options"
  # shellcheck disable=SC2086
  "$runtime" --image "$work/model.img" --sim --circle --bitrate 1000000 $options | sed -n '/^tip vs/,$p'
done
