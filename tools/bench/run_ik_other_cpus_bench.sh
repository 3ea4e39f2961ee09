#!/usr/bin/env bash
# The IK demo-model tests' convergence counts as other x86-64 CPUs get them.
# The demo's image (700 samples, seed 1, 50 held out, as qemu.golden makes
# it) is trained with five kernel sets: OpenBLAS's core type forced, and
# glibc's maths with or without its FMA/AVX variants. Each image's target
# sets are solved by the test (host_tests/model/ik_demo_model_test.cpp) with
# the host's AVX2 GP loops and with the portable ones (a second build,
# -DCDCR_MODEL_ARCH=portable), for three target seeds. Prints one row per
# run: kernel set, GP loops, seed offset, then the counts of the four target
# sets (near straight, paper workspace, full range, one segment at its limit).
#
#   bash tools/bench/run_ik_other_cpus_bench.sh
#
# The kernel sets must run on this CPU (Sandybridge needs AVX, Zen and
# Haswell AVX2). Everything stays in $BUILD_DIR/ik_other_cpus/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

source tools/bench/bench_build.sh

bench_work ik_other_cpus base "-DCDCR_BUILD_TOOLS=ON" cdcr test_model_ik_demo_model
portable_dir=$work_dir/portable-build
cmake -S . -B "$portable_dir" -DCMAKE_BUILD_TYPE=Release -DCDCR_MODEL_ARCH=portable -DCDCR_BUILD_TOOLS=OFF \
  -DCDCR_BUILD_BENCHMARKS=OFF --log-level=WARNING >/dev/null
cmake --build "$portable_dir" -j"$(nproc)" --target test_model_ik_demo_model >/dev/null

no_fma=glibc.cpu.hwcaps=-AVX,-AVX2,-FMA,-FMA4
kernel_sets=(
  "zen OPENBLAS_CORETYPE=Zen"
  "haswell OPENBLAS_CORETYPE=Haswell"
  "sandybridge OPENBLAS_CORETYPE=Sandybridge GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA"
  "nehalem OPENBLAS_CORETYPE=Nehalem GLIBC_TUNABLES=$no_fma"
  "prescott OPENBLAS_CORETYPE=Prescott GLIBC_TUNABLES=$no_fma"
)

echo "kernel_set gp_loops seed_offset near_straight paper_workspace full_range at_limit"
for kernel_set in "${kernel_sets[@]}"; do
  read -r name kernel_env <<<"$kernel_set"
  image_dir=$work_dir/$name
  mkdir -p "$image_dir"
  # shellcheck disable=SC2086  # the kernel set's variables, split on purpose
  env $kernel_env "$cdcr" simulate --samples 700 --seed 1 --out "$image_dir/robot.csv" >/dev/null
  # shellcheck disable=SC2086
  env $kernel_env "$cdcr" train --data "$image_dir/robot.csv" --holdout 50 --out "$image_dir/model.img" \
    >"$image_dir/train.log" 2>&1
  for loops in avx2 portable; do
    test_binary=$build_dir/host_tests/test_model_ik_demo_model
    [[ $loops == portable ]] && test_binary=$portable_dir/host_tests/test_model_ik_demo_model
    for offset in 0 1 2; do
      report=$image_dir/$loops-$offset.json
      # The floors may fail here: the counts are what this prints.
      # shellcheck disable=SC2086
      env $kernel_env CDCR_DEMO_MODEL_IMAGE="$image_dir/model.img" CDCR_IK_TARGET_SEED_OFFSET=$offset \
        "$test_binary" --gtest_output=json:"$report" >/dev/null || true
      /usr/bin/python3 - "$report" "$name" "$loops" "$offset" <<'PYTHON'
import json
import sys

counts = {}
for case in json.load(open(sys.argv[1]))["testsuites"][0]["testsuite"]:
    for key in ("converged", "full_range_converged", "at_limit_converged"):
        if key in case:
            counts[(case["name"], key)] = case[key]
order = [("NearStraightPoseTargetsConvergeFromStraight", "converged"),
         ("PaperWorkspacePoseTargetsConvergeFromStraight", "converged"),
         ("FullRangeAndLimitPoseTargetsConvergeFromStraight", "full_range_converged"),
         ("FullRangeAndLimitPoseTargetsConvergeFromStraight", "at_limit_converged")]
print(*sys.argv[2:], *(counts[key] for key in order))
PYTHON
    done
  done
done
