#!/bin/sh
# zynqmp.dependencies: what the other zynqmp.* tests need, the arm-none-eabi
# toolchain with newlib and its C++ library for the Cortex-R5F, and QEMU's
# aarch64 system emulator (the xlnx-zcu102 machine).
#   check_dependencies.sh <arm-none-eabi-g++> <arm-none-eabi-nm> <qemu-system-aarch64>
group=zynqmp install_group=cross
. "$(dirname "$0")/../support/missing_dependency.sh"

require_program arm-none-eabi-g++ "$1"
require_program arm-none-eabi-nm "$2"
require_program qemu-system-aarch64 "$3"
# newlib and its C++ library are packages of their own; the compiler names a
# library it cannot find by its bare name.
for library in libc_nano.a libstdc++_nano.a; do
  found=$("$1" -mthumb -mcpu=cortex-r5 -mfloat-abi=hard -mfpu=vfpv3-d16 -print-file-name="$library")
  [ "$found" != "$library" ] || missing "$library (newlib) for the Cortex-R5F not found by $1"
done
"$3" -machine help | grep -q '^xlnx-zcu102 ' || missing "$3 has no xlnx-zcu102 machine"
echo "zynqmp: arm-none-eabi toolchain, newlib and qemu-system-aarch64 (xlnx-zcu102) present"
