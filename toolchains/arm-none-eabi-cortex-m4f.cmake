# Cortex-M4F with the single-precision FPU (fpv4-sp-d16), as on QEMU's mps2-an386.
set(CDCR_ARM_CPU cortex-m4)
set(CDCR_ARM_FPU fpv4-sp-d16)
set(CDCR_BOARD mps2-an386)
# The GP loops' architecture code (model/arch/fpv4; FPv4: block loads).
set(CDCR_MODEL_ARCH fpv4 CACHE STRING "Architecture code of the GP loops: portable, fpv4 or fpv5")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
