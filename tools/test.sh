#!/usr/bin/env bash
# Builds everything in Release and runs every test. Extra arguments go to
# ctest, e.g. `bash tools/test.sh -L model`.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/install-deps.sh base sklearn fuzz uml cross
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release --log-level=WARNING
cmake --build build -j"$(nproc)"
# ctest's summary must be the last thing printed: CI reads it from the tail.
exec ctest --test-dir build --output-on-failure --no-label-summary -j"$(nproc)" "$@"
