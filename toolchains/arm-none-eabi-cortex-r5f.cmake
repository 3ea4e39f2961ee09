# Cortex-R5F (ARMv7-R) with the VFPv3-D16 FPU (single and double precision,
# 16 double registers), hard float, as the real-time cores of the Zynq
# UltraScale+ MPSoC on QEMU's xlnx-zcu102. The same gcc-arm-none-eabi and
# newlib as the Cortex-M boards. C and C++ compile to Thumb-2 (the common
# file's -mthumb), which the R5 runs as well as ARM code; the exception
# vectors and the start-up are ARM-state assembly (hal/zynqmp/src/vectors.S).
set(CDCR_ARM_CPU cortex-r5)
set(CDCR_ARM_FPU vfpv3-d16)
set(CDCR_BOARD xlnx-zcu102)
# The GP loops' architecture code: the portable loops until the R5F's own
# are measured (the fpv4 and fpv5 codes are tuned on M-profile pipelines).
set(CDCR_MODEL_ARCH portable CACHE STRING "Architecture code of the GP loops: portable, fpv4 or fpv5")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
