# Sourced by the run_*_bench.sh scripts, from the repository's root: the
# Release build they measure, and the simulator's noise floor they compare to.

build_dir=${BUILD_DIR:-build}

# bench_build [--show-build] DEPS CMAKE_OPTIONS TARGET...
# Installs the dependency groups DEPS (tools/install-deps.sh), configures
# $build_dir in Release with the extra CMAKE_OPTIONS (either may list several,
# separated by spaces) and builds the targets, showing the build's output only
# with --show-build.
bench_build() {
  local show_build=0
  if [[ $1 == --show-build ]]; then
    show_build=1
    shift
  fi
  local deps=$1 cmake_options=$2
  shift 2
  # shellcheck disable=SC2086  # word lists, split on purpose
  bash tools/install-deps.sh $deps
  # shellcheck disable=SC2086
  cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release $cmake_options --log-level=WARNING >/dev/null
  if ((show_build)); then
    cmake --build "$build_dir" -j"$(nproc)" --target "$@"
  else
    cmake --build "$build_dir" -j"$(nproc)" --target "$@" >/dev/null
  fi
}

# bench_work NAME DEPS CMAKE_OPTIONS TARGET...
# What every bench starts with: bench_build (DEPS, CMAKE_OPTIONS, TARGET... as
# there), then its output folder $build_dir/NAME made; sets work_dir to it
# and cdcr to the built command line tool.
bench_work() {
  local name=$1
  shift
  bench_build "$@"
  work_dir=$build_dir/$name
  mkdir -p "$work_dir"
  cdcr=$build_dir/bin/cdcr
}

# seed_option DEFAULT [--seed S]
# Prints the seed of a bench's optional --seed S argument, DEFAULT without it.
seed_option() {
  if [[ ${2:-} == --seed ]]; then echo "$3"; else echo "$1"; fi
}

# noise_floor SIMULATE_JSON
# Prints the noise floor of a `cdcr simulate --json` report as --noise-floor
# takes it: position_mm,orientation_deg.
noise_floor() {
  /usr/bin/python3 - "$1" <<'PYTHON'
import json
import sys

floor = json.load(open(sys.argv[1]))["noise_floor"]
print("{},{}".format(floor["position_mm"], floor["orientation_deg"]))
PYTHON
}
