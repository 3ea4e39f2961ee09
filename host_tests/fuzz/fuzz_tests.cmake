# ctest entries for the libFuzzer targets (label `fuzz`), included from
# host_tests/CMakeLists.txt. The fuzzers are a clang sub-build of
# host_tests/fuzz into <build>/fuzz: the fuzz.build test configures and builds
# it once (a fixture), then each fuzz.<name> test runs one fuzzer for
# CDCR_FUZZ_SECONDS with ASan and UBSan. Any crash, sanitizer report, leak,
# timeout or out-of-memory makes libFuzzer exit non-zero and fails the test;
# the input that triggered it is left in <build>/fuzz/artifacts.
#
# Needs clang++ and its libFuzzer/sanitizer runtimes (Debian: clang and
# libclang-rt-14-dev, plus llvm-14 for symbolized reports; `bash
# tools/install-deps.sh fuzz`). fuzz.dependencies checks for them, and every
# other fuzz test requires it: without them the group fails, naming the
# install command.

find_program(CDCR_CLANGXX NAMES clang++ clang++-14 DOC "clang++ for the libFuzzer targets")
set(CDCR_FUZZ_SECONDS 10 CACHE STRING "How long ctest runs each fuzzer (seconds)")

set(fuzz_dir ${CMAKE_BINARY_DIR}/fuzz)

cdcr_add_dependency_check(fuzz
  COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/check_dependencies.sh ${CDCR_CLANGXX} ${fuzz_dir}/dependency-probe)

# Debian installs the symbolizer under a versioned name only (llvm-14), where
# the sanitizers do not look for it by themselves.
find_program(CDCR_LLVM_SYMBOLIZER NAMES llvm-symbolizer llvm-symbolizer-14 HINTS /usr/lib/llvm-14/bin)
set(fuzz_env UBSAN_OPTIONS=print_stacktrace=1)
if(CDCR_LLVM_SYMBOLIZER)
  list(APPEND fuzz_env ASAN_SYMBOLIZER_PATH=${CDCR_LLVM_SYMBOLIZER} UBSAN_SYMBOLIZER_PATH=${CDCR_LLVM_SYMBOLIZER})
endif()

add_test(NAME fuzz.build
         COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${CMAKE_CURRENT_LIST_DIR} -DBINARY_DIR=${fuzz_dir}
                 -DCXX=${CDCR_CLANGXX} -DCDCR_SOURCE_DIR=${PROJECT_SOURCE_DIR} "-DGENERATOR=${CMAKE_GENERATOR}"
                 -P ${CMAKE_CURRENT_LIST_DIR}/build_fuzzers.cmake)
# COST: started early (see host_tests/qemu/CMakeLists.txt).
set_tests_properties(fuzz.build PROPERTIES LABELS fuzz FIXTURES_SETUP cdcr_fuzzers TIMEOUT 1200 COST 500)
cdcr_require_dependency_check(fuzz fuzz.build)

# cdcr_fuzz_test(<name> SEEDS <seed dir> [FLAGS <libFuzzer flags...>])
function(cdcr_fuzz_test name)
  cmake_parse_arguments(ARG "" "SEEDS" "FLAGS" ${ARGN})
  # Through `cmake -E env` so that ctest does not look for the executable
  # before fuzz.build has made it.
  add_test(NAME fuzz.${name}
           COMMAND ${CMAKE_COMMAND} -E env ${fuzz_env} ${fuzz_dir}/${name}_fuzz
                   -max_total_time=${CDCR_FUZZ_SECONDS} -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
                   -artifact_prefix=${fuzz_dir}/artifacts/${name}- ${ARG_FLAGS}
                   ${fuzz_dir}/corpus/${name} ${fuzz_dir}/seeds/${ARG_SEEDS})
  math(EXPR timeout "${CDCR_FUZZ_SECONDS} + 120")
  # The exit code already fails the test; the patterns also catch a report
  # from a run that somehow exits 0.
  set_tests_properties(fuzz.${name} PROPERTIES
    LABELS fuzz
    FIXTURES_REQUIRED cdcr_fuzzers
    TIMEOUT ${timeout}
    FAIL_REGULAR_EXPRESSION "ERROR: AddressSanitizer;ERROR: LeakSanitizer;runtime error:;ERROR: libFuzzer;deadly signal")
  cdcr_require_dependency_check(fuzz fuzz.${name})
endfunction()

cdcr_fuzz_test(image_parser SEEDS image FLAGS -max_len=8192)
cdcr_fuzz_test(dataset_csv SEEDS csv FLAGS -dict=${CMAKE_CURRENT_LIST_DIR}/csv.dict)
cdcr_fuzz_test(mocap_tsv SEEDS tsv FLAGS -dict=${CMAKE_CURRENT_LIST_DIR}/tsv.dict -max_len=8192)
