#!/bin/sh
# socketcan.dependencies: what the bus test in User-Mode Linux needs, the UML
# kernel with its CAN modules, and the guest's tools (can-utils, ip, insmod),
# which it finds on its own fixed PATH (uml_init.sh), and the FD test's
# client: Debian's python3 with python-can and canmatrix.
#   check_dependencies.sh <linux.uml> <UML modules dir> <cansend> <candump> <cangen> <ip> <insmod> <python3>
group=socketcan install_group=uml
. "$(dirname "$0")/../support/missing_dependency.sh"

require_program linux.uml "$1"
ls "$2"/*/kernel/drivers/net/can/vcan.ko > /dev/null 2>&1 || missing "the UML kernel's vcan module not found under $2"
require_program cansend "$3"
require_program candump "$4"
require_program cangen "$5"
require_program ip "$6"
require_program insmod "$7"
require_program python3 "$8"
"$8" -c "import can, canmatrix" 2> /dev/null || missing "python-can and canmatrix not importable by $8"
echo "socketcan: linux.uml with vcan, can-utils, ip, insmod, python-can and canmatrix present"
