# cmake -DQEMU=<qemu-system-aarch64> -DELF= -DWORK_DIR= [-DICOUNT=shift] [-DTIMEOUT_SECONDS=900]
#       [-DSECOND_CORE=ON] [-DEXPECT_STATUS=n -DEXPECT=regex | -DRUN_SECONDS=s -DEXPECT=regex] -P run_r5f.cmake
# Runs a program on the first Cortex-R5F of QEMU's xlnx-zcu102 (with
# SECOND_CORE, on both, hal/zynqmp second_core.hpp), with both CAN
# controllers on one emulated bus. The R5Fs start powered off and -kernel
# alone does not start them: QEMU starts stopped (-S), and QMP on stdin
# powers the cores on, resets the machine (the loader puts every core at the
# ELF's entry) and continues. The program's console is uart0, written to
# WORK_DIR/uart.log and printed here; its exit status comes through
# semihosting, from either core. The verdict, on the UART output, is the
# Cortex-M boards' (host_tests/qemu/qemu_verdict.cmake).
# With ICOUNT, each instruction advances the virtual clock by 2^ICOUNT ns.
foreach(variable QEMU ELF WORK_DIR)
  if(NOT ${variable})
    message(FATAL_ERROR "run_r5f.cmake: ${variable} is not set")
  endif()
endforeach()
# A guard against a hung QEMU only: the programs judge time on the guest's
# own clock, and a host busy with other work may take many times a quiet
# one's 30 s (over 300 s, seen with a second suite running beside).
set(seconds 900)
if(DEFINED TIMEOUT_SECONDS)
  set(seconds ${TIMEOUT_SECONDS})
endif()
if(DEFINED RUN_SECONDS)
  set(seconds ${RUN_SECONDS})
endif()
set(icount_args)
if(DEFINED ICOUNT)
  set(icount_args -icount shift=${ICOUNT})
endif()

file(MAKE_DIRECTORY ${WORK_DIR})
set(uart_log ${WORK_DIR}/uart.log)
set(qmp_commands ${WORK_DIR}/start_rpu.qmp)
file(REMOVE ${uart_log})
set(cores 0)
if(SECOND_CORE)
  list(APPEND cores 1)
endif()
set(power_on "")
foreach(core IN LISTS cores)
  string(APPEND power_on
    "{\"execute\":\"qom-set\",\"arguments\":{\"path\":\"/machine/soc/rpu-cluster/rpu-cpu[${core}]\",\"property\":\"start-powered-off\",\"value\":false}}\n")
endforeach()
file(WRITE ${qmp_commands}
  "{\"execute\":\"qmp_capabilities\"}\n"
  "${power_on}"
  "{\"execute\":\"system_reset\"}\n"
  "{\"execute\":\"cont\"}\n")

# -smp 6: four A53s and the two R5Fs; the A53s stay powered off. Under
# -icount all cores take turns on one virtual clock (second_core.hpp).
# The bus object must not be called canbus0 (an ambiguous QOM path).
# -audiodev none: the DisplayPort's audio would otherwise look for a sound card.
# timeout -k: under -icount a QEMU whose guest spins may not act on SIGTERM.
execute_process(
  COMMAND timeout -k 5 ${seconds} ${QEMU} -M xlnx-zcu102 -smp 6 -global xlnx-zynqmp.boot-cpu=rpu-cpu[0] ${icount_args}
          -object can-bus,id=r5f_can_bus -machine canbus0=r5f_can_bus,canbus1=r5f_can_bus
          -audiodev none,id=no_audio -display none -monitor none -serial file:${uart_log}
          -semihosting-config enable=on,target=native -kernel ${ELF} -qmp stdio -S
  INPUT_FILE ${qmp_commands}
  OUTPUT_VARIABLE qmp_output
  ERROR_VARIABLE qemu_errors
  RESULT_VARIABLE status)
set(output "")
if(EXISTS ${uart_log})
  file(READ ${uart_log} output)
endif()
message("${output}")
if(NOT status EQUAL 0 AND qemu_errors)
  message("${qemu_errors}")
endif()
# A QEMU that never resumed did not start the R5F: the QMP exchange says why.
if(NOT status EQUAL 0 AND NOT status EQUAL 124 AND NOT qmp_output MATCHES "\"RESUME\"")
  message("QMP:\n${qmp_output}")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/../qemu/qemu_verdict.cmake)
cdcr_qemu_verdict("${ELF} on the zcu102 R5F" "${status}" "${output}")
