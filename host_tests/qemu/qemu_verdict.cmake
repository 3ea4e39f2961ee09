# The verdict on a program that ran under QEMU, include()d by run_qemu.cmake
# (Cortex-M boards) and host_tests/zynqmp/run_r5f.cmake (the R5F board).
#
# cdcr_qemu_verdict(<what> <status> <output>): <what> names the program and
# the machine in the errors, <status> is the exit status of `timeout QEMU ...`
# (124: still running when the time was up), <output> what the program wrote.
# A program that ends passes when QEMU exits with 0 (the program's own
# status) and it printed PASS; with EXPECT_STATUS, when it exits with that
# status and its output matches EXPECT (a program that must fail in a given
# way). A program that runs forever (RUN_SECONDS) passes when it is still
# running after that long and its output matched EXPECT.
function(cdcr_qemu_verdict what status output)
  string(REPLACE "\\n" "\n" expected "${EXPECT}")
  if(DEFINED RUN_SECONDS)
    if(NOT status EQUAL 124)
      message(FATAL_ERROR "${what}: stopped with status ${status} instead of running on")
    endif()
  elseif(status EQUAL 124)
    message(FATAL_ERROR "${what}: timed out after ${seconds} s")
  elseif(DEFINED EXPECT_STATUS)
    if(NOT status EQUAL EXPECT_STATUS)
      message(FATAL_ERROR "${what}: exit status ${status} instead of ${EXPECT_STATUS}")
    endif()
  else()
    if(NOT status EQUAL 0)
      message(FATAL_ERROR "${what}: exit status ${status}")
    endif()
    if(NOT output MATCHES "(^|\n)PASS\n")
      message(FATAL_ERROR "${what}: no PASS line")
    endif()
    return()
  endif()
  if(NOT output MATCHES "${expected}")
    message(FATAL_ERROR "${what}: output does not match '${EXPECT}'")
  endif()
endfunction()
