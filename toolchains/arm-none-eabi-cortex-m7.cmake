# Cortex-M7 with the double-precision FPU (fpv5-d16), as on QEMU's mps2-an500.
set(CDCR_ARM_CPU cortex-m7)
set(CDCR_ARM_FPU fpv5-d16)
set(CDCR_BOARD mps2-an500)
# The GP loops' architecture code (model/arch/fpv5; FPv5: block loads and the assembly GP mean loop).
set(CDCR_MODEL_ARCH fpv5 CACHE STRING "Architecture code of the GP loops: portable, fpv4 or fpv5")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
