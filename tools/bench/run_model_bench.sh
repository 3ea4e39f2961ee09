#!/usr/bin/env bash
# Builds the model benchmarks in Release and prints a markdown table of median
# CPU time per call and its ratio to the baseline measured in the same run.
# Only the ratios are comparable between machines or between noisy runs.
#
#   bash tools/bench/run_model_bench.sh [benchmark flags...]
#   BUILD_DIR=build-bench bash tools/bench/run_model_bench.sh --benchmark_filter=ik
#
# The raw results stay in $BUILD_DIR/model_bench.json.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

build_dir=${BUILD_DIR:-build}
results_json=$build_dir/model_bench.json
console_log=$build_dir/model_bench.log

bash tools/install-deps.sh base
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCDCR_BUILD_TOOLS=ON -DCDCR_BUILD_BENCHMARKS=ON \
  --log-level=WARNING >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target cdcr-bench-model

echo "Running benchmarks (console output in $console_log)..."
"$build_dir/bin/cdcr-bench-model" \
  --benchmark_repetitions=15 \
  --benchmark_report_aggregates_only=true \
  --benchmark_min_time=0.05 \
  --benchmark_out="$results_json" \
  --benchmark_out_format=json \
  "$@" >"$console_log" 2>&1 || {
  tail -n 20 "$console_log" >&2
  exit 1
}

cpu_model=$(sed -n 's/^model name[[:space:]]*:[[:space:]]*//p' /proc/cpuinfo | head -n 1)
revision=$(git describe --always --dirty 2>/dev/null || echo unknown)

python3 - "$results_json" "$(nproc)" "${cpu_model:-unknown}" "$revision" <<'PYTHON'
import json
import sys

results_path, cpu_count, cpu_model, revision = sys.argv[1:5]
with open(results_path) as f:
    results = json.load(f)

to_ns = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
medians = [
    b for b in results["benchmarks"]
    if b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median"
]
if not medians:
    sys.exit("no median aggregates in " + results_path)

def cpu_ns(b):
    return b["cpu_time"] * to_ns[b["time_unit"]]

baseline = next((b for b in medians if b["run_name"].startswith("baseline")), None)
baseline_ns = cpu_ns(baseline) if baseline else None

context = results["context"]
print(f"Model benchmarks, {context['date'][:10]}, revision {revision}")
print(f"CPU: {cpu_model}, nproc {cpu_count}; library build: {context.get('library_build_type', '?')}")
print(f"{medians[0].get('repetitions', '?')} repetitions, median CPU time per call; "
      f"ratio to {baseline['run_name'] if baseline else 'no baseline in this run'}")
print()
print("| benchmark | median ns/call | ratio to baseline | IK iterations | converged |")
print("|---|---:|---:|---:|---:|")
for b in medians:
    ns = cpu_ns(b)
    ratio = f"{ns / baseline_ns:.2f}" if baseline_ns else "-"
    iterations = f"{b['ik_iterations']:.2f}" if "ik_iterations" in b else ""
    converged = f"{100 * b['converged']:.1f}%" if "converged" in b else ""
    print(f"| `{b['run_name']}` | {ns:.1f} | {ratio} | {iterations} | {converged} |")
PYTHON
