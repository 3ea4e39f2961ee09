# Cortex-M4F with the single-precision FPU (fpv4-sp-d16), as on QEMU's mps2-an386.
set(CDCR_CORTEXM_CPU cortex-m4)
set(CDCR_CORTEXM_FPU fpv4-sp-d16)
set(CDCR_CORTEXM_BOARD mps2-an386)
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
