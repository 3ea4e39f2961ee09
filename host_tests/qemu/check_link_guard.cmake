# cmake -DBINARY_DIR= [-DPROBE_TARGET=cdcr_qemu_heap_probe] -P check_link_guard.cmake
# The guard's own test: a board program that calls malloc must fail to link,
# and the error must come from the guard (the undefined __wrap_malloc).
if(NOT BINARY_DIR)
  message(FATAL_ERROR "check_link_guard.cmake: BINARY_DIR is not set")
endif()
if(NOT PROBE_TARGET)
  set(PROBE_TARGET cdcr_qemu_heap_probe)
endif()
execute_process(
  COMMAND ${CMAKE_COMMAND} --build ${BINARY_DIR} --target ${PROBE_TARGET}
  OUTPUT_VARIABLE output ERROR_VARIABLE output RESULT_VARIABLE status)
if(status EQUAL 0)
  message(FATAL_ERROR "a program calling malloc linked: the heap guard is not active")
endif()
if(NOT output MATCHES "undefined reference to `__wrap_malloc'")
  message(FATAL_ERROR "the heap probe failed to build, but not at the guard:\n${output}")
endif()
string(REGEX MATCH "[^\n]*undefined reference to `__wrap_malloc'" line "${output}")
message("link refused as expected: ${line}")
