#!/bin/sh
# qemu.dependencies: what the other qemu.* tests need, the arm-none-eabi
# toolchain with newlib and its C++ library, and QEMU.
#   check_dependencies.sh <arm-none-eabi-g++> <arm-none-eabi-nm> <arm-none-eabi-size> <qemu-system-arm>
group=qemu install_group=cross
. "$(dirname "$0")/../support/missing_dependency.sh"

require_program arm-none-eabi-g++ "$1"
require_program arm-none-eabi-nm "$2"
require_program arm-none-eabi-size "$3"
require_program qemu-system-arm "$4"
# newlib and its C++ library are packages of their own; the compiler names a
# library it cannot find by its bare name.
for library in libc_nano.a libstdc++_nano.a; do
  found=$("$1" -mthumb -mcpu=cortex-m4 -mfloat-abi=hard -mfpu=fpv4-sp-d16 -print-file-name="$library")
  [ "$found" != "$library" ] || missing "$library (newlib) not found by $1"
done
echo "qemu: arm-none-eabi toolchain, newlib and qemu-system-arm present"
