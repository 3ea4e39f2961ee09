#!/usr/bin/env bash
# The time and frames of one `cdcr deploy` on vcan0 inside User-Mode Linux:
# a model image near the slot's 64 KiB (820 samples of the simulated robot,
# plain `cdcr train`: an exact 820-point model with its variance block,
# 65,084 bytes) sent to `cdcr-runtime --flash-dir` while the drives' cable
# frames flow (tools/bench/deploy_timing_guest.sh runs in the guest).
#
#   bash tools/bench/run_deploy_bench.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

build_dir=${BUILD_DIR:-build}
work=$(realpath -m "$build_dir/deploy_bench")
bash tools/install-deps.sh base uml
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr cdcr-runtime socketcan_check >/dev/null
mkdir -p "$work"
"$build_dir/bin/cdcr" simulate --samples 820 --seed 5 --out "$work/data.csv" >/dev/null
"$build_dir/bin/cdcr" train --data "$work/data.csv" --out "$work/deploy.img" >"$work/train.log"
uml=$(sed -n 's/^CDCR_LINUX_UML:FILEPATH=//p' "$build_dir/CMakeCache.txt")
bash host_tests/socketcan/run_in_uml.sh "${uml:-/usr/bin/linux.uml}" "$(realpath "$build_dir/bin/cdcr-runtime")" \
  "$(realpath "$build_dir/host_tests/socketcan_check")" "$work" ../../tools/bench/deploy_timing_guest.sh \
  "$(realpath "$build_dir/bin/cdcr")"
grep '^bus_test: deploy of' "$work/console.log"
