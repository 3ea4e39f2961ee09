# cmake -DQEMU= -DMACHINE= -DCPU= -DELF= [-DICOUNT=shift]
#       [-DEXPECT_STATUS=n -DEXPECT=regex | -DRUN_SECONDS=s -DEXPECT=regex] -P run_qemu.cmake
# Runs a semihosting program under QEMU and judges it (qemu_verdict.cmake).
# The program's output goes to stdout through the semihosting chardev, the
# UART nowhere. With ICOUNT, each instruction
# advances the virtual clock by 2^ICOUNT ns.
set(icount_args)
if(DEFINED ICOUNT)
  set(icount_args -icount shift=${ICOUNT})
endif()
# A guard against a hung QEMU only (see run_r5f.cmake): the budgets count
# instructions, and a busy host may take several times a quiet one's time.
set(seconds 900)
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
include(${CMAKE_CURRENT_LIST_DIR}/qemu_verdict.cmake)
cdcr_qemu_verdict("${ELF} on ${MACHINE}" "${status}" "${output}")
