#!/usr/bin/env bash
# Boots User-Mode Linux on the host's own root filesystem (hostfs) and runs
# the bus test inside it, so it needs no CAN support in the host kernel.
#   run_in_uml.sh <linux.uml> <runtime> <checker> <work dir>
set -uo pipefail
uml=$1 runtime=$2 checker=$3 work=$4
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
mkdir -p "$work/tmp"
console=$work/console.log

# UML keeps its memory in a file under TMPDIR (which must allow exec
# mappings), and aborts without HOME.
HOME=${HOME:-$work} TMPDIR=$work/tmp timeout 60 "$uml" mem=512M root=/dev/root rootfstype=hostfs rootflags=/ rw \
  init="$here/uml_init.sh" con0=null,fd:1 con=null quiet \
  CDCR_TEST_DRIVER="$here/bus_test.sh" CDCR_RUNTIME="$runtime" CDCR_CHECK="$checker" CDCR_WORK_DIR="$work" \
  </dev/null 2>&1 | tee "$console"
status=$?
if [[ $status -ne 0 ]]; then
  echo "run_in_uml: the guest exited with status $status"
  exit 1
fi
# The guest's exit status is the driver's; its own marker is the second witness.
grep -q "^SOCKETCAN_TEST_PASS" "$console" || { echo "run_in_uml: no pass marker"; exit 1; }
