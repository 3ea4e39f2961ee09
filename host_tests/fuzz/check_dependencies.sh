#!/bin/sh
# fuzz.dependencies: what the libFuzzer targets need, clang++ and its fuzzer
# and sanitizer runtimes (a package of their own: clang alone compiles, then
# fails to link -fsanitize=fuzzer).
#   check_dependencies.sh <clang++> <scratch dir>
group=fuzz install_group=fuzz
. "$(dirname "$0")/../support/missing_dependency.sh"

require_program clang++ "$1"
mkdir -p "$2"
printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' > "$2/probe.cpp"
"$1" -fsanitize=fuzzer,address,undefined "$2/probe.cpp" -o "$2/probe" > "$2/probe.log" 2>&1 ||
  missing "$1 cannot link -fsanitize=fuzzer,address,undefined (libFuzzer runtime): $(grep -m1 -i error "$2/probe.log")"
echo "fuzz: clang++ with the libFuzzer and sanitizer runtimes present"
