#!/usr/bin/env bash
# Builds everything in Release and runs every test. Extra arguments go to
# ctest, e.g. `bash tools/test.sh -L model`.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

started=$SECONDS
# The build needs only the base packages. The test groups' packages (the
# cross toolchain and QEMU, clang, User-Mode Linux, scikit-learn, Node.js
# with the npm canopen stack and the view's clients, Chromium) install while
# it runs: apt and npm wait on the network and the disk, the build on the
# CPU.
bash tools/install-deps.sh base
group_log=$(mktemp)
bash tools/install-deps.sh sklearn fuzz uml cross canopen view browser >"$group_log" 2>&1 &
group_install=$!
# The measuring programs (cdcr-bench-*) are not built here: no test runs
# them, and they cost about 75 s of a core. Each tools/bench/run_*.sh
# configures them on and builds its own.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCDCR_BUILD_BENCHMARKS=OFF --log-level=WARNING
cmake --build build -j"$(nproc)"
build_s=$((SECONDS - started))
if ! wait "$group_install"; then
  cat "$group_log" >&2
  exit 1
fi
cat "$group_log"
rm -f "$group_log"
# The first configure ran before the test groups' packages were there, so the
# groups' dependency checks recorded the cross compiler, QEMU, clang and
# User-Mode Linux as missing. Configure again now that they are installed
# (find_program searches again for what it did not find) and build what that
# adds; with everything already found this is a no-op of a few seconds.
rebuild_log=build/reconfigure.log
if ! { cmake -S . -B build --log-level=WARNING && cmake --build build -j"$(nproc)"; } >"$rebuild_log" 2>&1; then
  tail -n 30 "$rebuild_log" >&2
  echo "test.sh: configuring again with the test groups' packages failed (log: $rebuild_log)" >&2
  exit 1
fi
# Where the time goes, before the tests (tools/bench/README.md, "Test suite time").
echo "test.sh: packages and build ${build_s} s, the test groups' packages and the second configure $((SECONDS - started - build_s)) s more; the tests follow"
# One test more than there are cores: the bus tests in User-Mode Linux and
# the QEMU replays, which run in real time, wait more than they compute.
# ctest's summary must be the last thing printed: CI reads it from the tail.
exec ctest --test-dir build --output-on-failure --no-label-summary -j"$(($(nproc) + 1))" "$@"
