# Cortex-M7 with the double-precision FPU (fpv5-d16), as on QEMU's mps2-an500.
set(CDCR_CORTEXM_CPU cortex-m7)
set(CDCR_CORTEXM_FPU fpv5-d16)
set(CDCR_CORTEXM_BOARD mps2-an500)
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
