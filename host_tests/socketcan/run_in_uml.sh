#!/usr/bin/env bash
# Boots User-Mode Linux on the host's own root filesystem (hostfs) and runs
# the bus test inside it, so it needs no CAN support in the host kernel.
#   run_in_uml.sh <linux.uml> <runtime> <checker> <work dir> [driver [cdcr [extra]]]
#   driver: the script the guest runs (bus_test.sh), cdcr: the CLI (deploy_test.sh),
#   extra: a file the driver reads (fd_bus_test.sh: the FD DBC)
#   CDCR_UML_TIMEOUT: seconds the whole guest may run (default 600)
#   CDCR_WAIT_SECONDS: passed to the driver (bus_test.sh)
set -uo pipefail
uml=$1 runtime=$2 checker=$3 work=$4 driver=${5:-bus_test.sh} cli=${6:-} extra=${7:-}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
mkdir -p "$work"
console=$work/console.log
# Generous, for a busy host: the driver's own waits have deadlines, so a
# stuck runtime fails well before this; it catches a guest that hangs.
guest_timeout=${CDCR_UML_TIMEOUT:-600}
# A guest boots in 2 to 10 s; one that has not started the driver by then
# has hung at boot (seen once in many runs on a busy host), and a new boot
# is cheap. What happens after the driver starts is never retried.
boot_seconds=120
boots=3

# UML keeps its memory in a file under TMPDIR, which must allow exec
# mappings; on a tmpfs (/dev/shm, when it allows them) that file never
# touches the disk.
if [[ -d /dev/shm && -w /dev/shm ]] && ! grep -qs ' /dev/shm [^ ]* [^ ]*noexec' /proc/mounts; then
  uml_tmp=$(mktemp -d /dev/shm/cdcr-uml.XXXXXX)
else
  uml_tmp=$(mktemp -d "$work/uml-tmp.XXXXXX")
fi
guest_pid=""
stop_guest() {
  # The guest is a session of its own: its helper processes go with it.
  [[ -n $guest_pid ]] || return 0
  kill -TERM -- "-$guest_pid" 2>/dev/null
  for _ in 1 2 3 4 5; do
    kill -0 "$guest_pid" 2>/dev/null || break
    sleep 1
  done
  kill -KILL -- "-$guest_pid" 2>/dev/null
  wait "$guest_pid" 2>/dev/null
  guest_pid=""
}
trap 'stop_guest; rm -rf "$uml_tmp"' EXIT

start_s=$SECONDS
status=1
for ((boot = 1; boot <= boots; boot++)); do
  boot_start_s=$SECONDS
  # UML aborts without HOME.
  HOME=${HOME:-$work} TMPDIR=$uml_tmp setsid -w "$uml" mem=512M root=/dev/root rootfstype=hostfs rootflags=/ rw \
    init="$here/uml_init.sh" con0=null,fd:1 con=null quiet \
    CDCR_TEST_DRIVER="$here/$driver" CDCR_CLI="$cli" CDCR_EXTRA="$extra" CDCR_RUNTIME="$runtime" CDCR_CHECK="$checker" CDCR_WORK_DIR="$work" \
    CDCR_WAIT_SECONDS="${CDCR_WAIT_SECONDS:-60}" \
    </dev/null >"$console" 2>&1 &
  guest_pid=$!
  started=false
  hung_at_boot=false
  while kill -0 "$guest_pid" 2>/dev/null; do
    if ! $started && grep -q '^bus_test: ' "$console"; then
      started=true
    fi
    if ! $started && ((SECONDS - boot_start_s > boot_seconds)); then
      hung_at_boot=true
      break
    fi
    if ((SECONDS - start_s > guest_timeout)); then
      cat "$console"
      echo "run_in_uml: the guest did not finish within $guest_timeout s"
      exit 1
    fi
    sleep 1
  done
  if $hung_at_boot; then
    stop_guest
    cat "$console"
    echo "run_in_uml: boot $boot did not start the test within $boot_seconds s; booting again"
    continue
  fi
  wait "$guest_pid"
  status=$?
  guest_pid=""
  break
done
if ((boot > boots)); then
  echo "run_in_uml: no boot out of $boots started the test"
  exit 1
fi
cat "$console"
echo "run_in_uml: the guest ran for $((SECONDS - start_s)) s, boot $boot"
if [[ $status -ne 0 ]]; then
  echo "run_in_uml: the guest exited with status $status"
  exit 1
fi
# The guest's exit status is the driver's; its own marker is the second witness.
grep -q "^SOCKETCAN_TEST_PASS" "$console" || { echo "run_in_uml: no pass marker"; exit 1; }
