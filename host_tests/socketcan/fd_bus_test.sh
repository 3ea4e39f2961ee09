#!/bin/sh
# The CAN FD bus test, run inside the guest: cdcr-runtime at 1 kHz on vcan
# with FD frames (MTU 72), streaming a target every period, against
# fd_client.py (python-can and the FD DBC read by canmatrix): first on one
# interface, then with the drives on a second one (--drives-can). Every
# frame the runtime sends must decode with the DBC, as an FD frame with
# bit-rate switching; the poses and setpoints are checked against the model
# library (socketcan_check fd-check).
#   CDCR_RUNTIME, CDCR_CHECK: host-built binaries; CDCR_EXTRA: the FD DBC;
#   CDCR_WORK_DIR: scratch space.
#
# The runtime's rate is the board's 1 kHz. Inside User-Mode Linux every
# system call is slow, so neither the runtime nor the client holds that
# rate and the input may turn stale now and then: the checks are on what
# the frames say, never on time (the simulated bus's tests check the
# timing, runtime.timed_bus_circle).
set -u
work=$CDCR_WORK_DIR
dbc=$CDCR_EXTRA
here=$(dirname "$0")
log=$work/none  # bus_waits.sh's fail copies the capture; this test keeps none
. "$here/bus_waits.sh"
image=$work/model.img

"$CDCR_CHECK" image "$image" || fail "cannot write the model image"
"$CDCR_CHECK" fd-values "$image" > "$work/values.txt" || fail "cannot compute the values"

# An interface carries FD frames with an MTU of 72 (CANFD_MTU, vcan's
# default), classical ones only with 16 (CAN_MTU): vcan0 and vcan1 (the
# drives) FD, vcan2 classical.
ip link set vcan0 down && ip link set vcan0 mtu 72 && ip link set vcan0 up || fail "cannot set vcan0's MTU"
for interface in vcan1 vcan2; do
  ip link add dev "$interface" type vcan && ip link set "$interface" txqueuelen 10000 || fail "cannot add $interface"
done
ip link set vcan1 mtu 72 && ip link set vcan2 mtu 16 && ip link set up vcan1 && ip link set up vcan2 ||
  fail "cannot bring up vcan1 and vcan2"

# FD on an interface without FD frames: one line, status 1.
"$CDCR_RUNTIME" --image "$image" --can vcan2 --can-format fd --seconds 0.1 > /dev/null 2> "$work/runtime.err"
status=$?
if [ "$status" -ne 1 ] || [ "$(wc -l < "$work/runtime.err")" -ne 1 ] || ! grep -q "CAN FD" "$work/runtime.err"; then
  fail "FD on a classical interface: status $status, $(cat "$work/runtime.err")"
fi
progress "FD on a classical interface refused: $(cat "$work/runtime.err")"

# run_phase <name> <client options> -- <runtime options>
run_phase() {
  name=$1
  shift
  client_options=""
  while [ "$1" != "--" ]; do
    client_options="$client_options $1"
    shift
  done
  shift
  "$CDCR_RUNTIME" --image "$image" --rate 1000 --streaming "$@" > "$work/runtime.$name.out" \
    2> "$work/runtime.$name.err" &
  runtime_pid=$!
  sleep 1
  kill -0 "$runtime_pid" 2>/dev/null || fail "$name: cdcr-runtime did not start: $(cat "$work/runtime.$name.err")"
  # shellcheck disable=SC2086
  /usr/bin/python3 "$here/fd_client.py" --dbc "$dbc" --values "$work/values.txt" $client_options \
    --summary "$work/summary.$name.txt"
  client_status=$?
  kill -INT "$runtime_pid"
  wait "$runtime_pid"
  runtime_status=$?
  echo "--- cdcr-runtime, $name"
  cat "$work/runtime.$name.err" "$work/runtime.$name.out"
  [ "$client_status" -eq 0 ] || fail "$name: the client failed"
  [ "$runtime_status" -eq 0 ] || fail "$name: cdcr-runtime exited with $runtime_status after SIGINT"
  grep -q "^cycles " "$work/runtime.$name.out" || fail "$name: cdcr-runtime printed no cycle statistics"
  "$CDCR_CHECK" fd-check "$image" "$work/summary.$name.txt" || fail "$name: the poses or setpoints"
  progress "$name done"
}

# One FD bus, 1 Mbit/s with a 5 Mbit/s data phase: within the budget.
run_phase one_bus --host vcan0 -- --can vcan0 --can-format fd-brs --bitrate 1000000 --data-bitrate 5000000
# The drives on vcan1, both FD buses at 1 / 2 Mbit/s.
run_phase two_buses --host vcan0 --drives vcan1 -- --can vcan0 --drives-can vcan1 --can-format fd-brs \
  --bitrate 1000000 --data-bitrate 2000000
report_drops
progress "all done"
echo "SOCKETCAN_TEST_PASS"
