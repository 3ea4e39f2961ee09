# Shared part of the arm-none-eabi toolchain files. The including file sets
# CDCR_ARM_CPU (the -mcpu value), CDCR_ARM_FPU (the -mfpu value) and
# CDCR_BOARD (the QEMU machine, and with it the board, the start-up code
# targets) first; it also sets CDCR_MODEL_ARCH, the GP loops' architecture
# code that model/ selects.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_AR arm-none-eabi-ar CACHE FILEPATH "")
set(CMAKE_RANLIB arm-none-eabi-ranlib CACHE FILEPATH "")
set(CMAKE_OBJCOPY arm-none-eabi-objcopy CACHE FILEPATH "")
set(CMAKE_NM arm-none-eabi-nm CACHE FILEPATH "")

# A test executable cannot link without the board's startup code and linker
# script, which the project itself provides.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(CDCR_BOARD ${CDCR_BOARD} CACHE STRING "QEMU machine (board) the start-up code targets: mps2-an500, mps2-an386, xlnx-zcu102")

set(_cdcr_arch_flags "-mcpu=${CDCR_ARM_CPU} -mthumb -mfpu=${CDCR_ARM_FPU} -mfloat-abi=hard")
# No exceptions, RTTI or atexit registration on the target; -fno-math-errno
# lets sqrtf compile to one instruction instead of a libm call.
set(_cdcr_common_flags "${_cdcr_arch_flags} -fno-math-errno -ffunction-sections -fdata-sections")
set(CMAKE_C_FLAGS_INIT "${_cdcr_common_flags}")
# Eigen's assertions go to the board's handler, not newlib's allocating
# assert (bare_metal_eigen_config.hpp).
set(CMAKE_CXX_FLAGS_INIT "${_cdcr_common_flags} -fno-exceptions -fno-rtti -fno-use-cxa-atexit -fno-threadsafe-statics -include ${CMAKE_CURRENT_LIST_DIR}/bare_metal_eigen_config.hpp")
set(CMAKE_ASM_FLAGS_INIT "${_cdcr_arch_flags}")
# nano newlib; the project's startup code replaces crt0, and its system calls
# go through semihosting, so libnosys only fills in the stubs nothing uses.
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_cdcr_arch_flags} --specs=nano.specs --specs=nosys.specs -nostartfiles -Wl,--gc-sections")

# Host programs and packages (Eigen is header-only) are found as usual;
# target libraries come from the toolchain's own sysroot.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
