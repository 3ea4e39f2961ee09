# cmake -DQEMU= -DMACHINE= -DCPU= -DELF= -P run_qemu.cmake
# Runs a semihosting program under QEMU; passes when QEMU exits with 0 (the
# program's own status) and the program printed PASS. The program's output
# goes to stdout through the semihosting chardev, the UART nowhere.
execute_process(
  COMMAND timeout 20 ${QEMU} -M ${MACHINE} -cpu ${CPU} -display none -monitor none -serial null
          -chardev stdio,id=sh0 -semihosting-config enable=on,target=native,chardev=sh0 -kernel ${ELF}
  OUTPUT_VARIABLE output
  ERROR_VARIABLE output
  RESULT_VARIABLE status)
message("${output}")
if(status EQUAL 124)
  message(FATAL_ERROR "${ELF} on ${MACHINE}: timed out")
endif()
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${ELF} on ${MACHINE}: exit status ${status}")
endif()
if(NOT output MATCHES "(^|\n)PASS\n")
  message(FATAL_ERROR "${ELF} on ${MACHINE}: no PASS line")
endif()
