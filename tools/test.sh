#!/usr/bin/env bash
# Builds everything in Release and runs every test. Extra arguments go to
# ctest, e.g. `bash tools/test.sh -L model`.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

started=$SECONDS
bash tools/install-deps.sh base sklearn fuzz uml cross
packages_s=$((SECONDS - started))
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release --log-level=WARNING
cmake --build build -j"$(nproc)"
build_s=$((SECONDS - started - packages_s))
# Where the time goes, before the tests (tools/bench/README.md, "Test suite time").
echo "test.sh: packages ${packages_s} s, configure and build ${build_s} s; the tests follow"
# ctest's summary must be the last thing printed: CI reads it from the tail.
exec ctest --test-dir build --output-on-failure --no-label-summary -j"$(nproc)" "$@"
