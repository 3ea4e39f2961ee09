#!/usr/bin/env bash
# Instruction counts and memory of the runtime on the Cortex-M boards, under
# QEMU: mps2-an500 (Cortex-M7, fpv5-d16) and mps2-an386 (Cortex-M4F,
# fpv4-sp-d16). Builds the host tools, trains the 700-point, 8-input model on
# the simulated robot (700 samples, seed 1, 50 held out to validate, the
# image fitted on all 700), cross-builds the
# board programs against it (the qemu.golden and qemu.build_* test fixtures),
# then runs cdcr_qemu_cycle_bench with `-icount shift=10` on each board and
# prints the size report of the deployable program.
#
#   bash tools/bench/run_qemu_bench.sh
#   BUILD_DIR=build-bench bash tools/bench/run_qemu_bench.sh
#
# With -icount shift=10 every instruction advances QEMU's virtual clock by
# 1024 ns; SysTick counts the 25 MHz core clock (40 ns), so instructions =
# ticks * 40 / 1024, exactly and repeatably. QEMU models no pipeline or
# caches: these are instruction counts, not cycles.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

build_dir=${BUILD_DIR:-build}

bash tools/install-deps.sh base cross
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr make_qemu_golden >/dev/null
echo "Building the board programs (qemu.golden, qemu.build_m7, qemu.build_m4f)..."
ctest --test-dir "$build_dir" -R '^qemu\.(golden|build_m7|build_m4f)$' --output-on-failure >"$build_dir/qemu_bench_build.log" 2>&1 || {
  tail -n 30 "$build_dir/qemu_bench_build.log" >&2
  exit 1
}

revision=$(git describe --always --dirty 2>/dev/null || echo unknown)
echo "Cortex-M instruction counts, $(date -u +%F), revision $revision, $(qemu-system-arm --version | head -n 1)"
for board in "m7 mps2-an500 cortex-m7" "m4f mps2-an386 cortex-m4"; do
  read -r name machine cpu <<<"$board"
  echo
  echo "== $machine ($cpu)"
  timeout 300 qemu-system-arm -M "$machine" -cpu "$cpu" -icount shift=10 -display none -monitor none -serial null \
    -chardev stdio,id=sh0 -semihosting-config enable=on,target=native,chardev=sh0 \
    -kernel "$build_dir/cross-$name/bin/cdcr_qemu_cycle_bench.elf" | grep -v '^case '
done
echo
bash tools/bench/cortexm_size_report.sh "$build_dir"/cross-m7/bin/cdcr_mps2_firmware.elf \
  "$build_dir"/cross-m4f/bin/cdcr_mps2_firmware.elf
