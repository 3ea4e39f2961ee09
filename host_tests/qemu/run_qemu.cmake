# cmake -DQEMU= -DMACHINE= -DCPU= -DELF= [-DICOUNT=shift] [-DRUN_SECONDS=s -DEXPECT=regex] -P run_qemu.cmake
# Runs a semihosting program under QEMU. A program that ends passes when QEMU
# exits with 0 (the program's own status) and it printed PASS. A program that
# runs forever (RUN_SECONDS) passes when it is still running after that long
# and its output matched EXPECT. The program's output goes to stdout through
# the semihosting chardev, the UART nowhere. With ICOUNT, each instruction
# advances the virtual clock by 2^ICOUNT ns.
set(icount_args)
if(DEFINED ICOUNT)
  set(icount_args -icount shift=${ICOUNT})
endif()
set(seconds 60)
if(DEFINED RUN_SECONDS)
  set(seconds ${RUN_SECONDS})
endif()
execute_process(
  COMMAND timeout ${seconds} ${QEMU} -M ${MACHINE} -cpu ${CPU} ${icount_args} -display none -monitor none -serial null
          -chardev stdio,id=sh0 -semihosting-config enable=on,target=native,chardev=sh0 -kernel ${ELF}
  OUTPUT_VARIABLE output
  ERROR_VARIABLE output
  RESULT_VARIABLE status)
message("${output}")
if(DEFINED RUN_SECONDS)
  if(NOT status EQUAL 124)
    message(FATAL_ERROR "${ELF} on ${MACHINE}: stopped with status ${status} instead of running on")
  endif()
  string(REPLACE "\\n" "\n" expected "${EXPECT}")
  if(NOT output MATCHES "${expected}")
    message(FATAL_ERROR "${ELF} on ${MACHINE}: output does not match '${EXPECT}'")
  endif()
  return()
endif()
if(status EQUAL 124)
  message(FATAL_ERROR "${ELF} on ${MACHINE}: timed out")
endif()
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${ELF} on ${MACHINE}: exit status ${status}")
endif()
if(NOT output MATCHES "(^|\n)PASS\n")
  message(FATAL_ERROR "${ELF} on ${MACHINE}: no PASS line")
endif()
