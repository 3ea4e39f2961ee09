#!/bin/sh
# The runtime with CiA 402 drives, run inside the guest (run_in_uml.sh):
# cdcr-runtime --drives cia402 on vcan0 against 16 simulated drives
# (tools/sim/cia402/drive_sim.js, one process per bus, four drives on each of
# vcan1..vcan4). From power-up every drive must be configured and enabled
# ("drives: operational after N ms" on stderr, N within operational_limit_ms); then
# uml_host_peer.py sends six pose targets on vcan0, one after the other: each
# must converge, the drives must reach their setpoints, and the pose
# published once the robot is still must be the target's and match
# cdcr-runtime --replay of the drives' positions there. Then two faults,
# each injected in a drive when the peer is ready for it (SIGUSR2 to its
# simulator): drive 3 of vcan3 sends an EMCY and drops out of Operation
# enabled (STATUS FAULT 14 drive_fault, FAULT_DETAIL 3, until the host's
# DRIVES_COMMAND recovers it), then drive 2 of vcan2 stops its heartbeat
# (FAULT 13 drive_silent, FAULT_DETAIL 2). Last, two runs from power-up
# with a fault at start-up: drive 2 of vcan2 refuses the write of 0x6060
# (SDO abort, FAULT 15 drive_refused, FAULT_DETAIL 2) and drive 3 of vcan4
# never answers (FAULT 13 after the boot timeout, FAULT_DETAIL 3).
#   CDCR_RUNTIME, CDCR_CHECK (socketcan_check): host-built binaries;
#   CDCR_EXTRA: the protocol's DBC; CDCR_WORK_DIR: scratch space.
#
# Inside User-Mode Linux four node processes and the runtime share one slow
# CPU, so the cycle is 20 Hz and the drives' timing generous; the peer
# prints the SYNC rate the guest sustained.
set -u
work=$CDCR_WORK_DIR
here=$(dirname "$0")
# shellcheck disable=SC2034
log=$work/none  # bus_waits.sh's fail copies a capture; this test keeps none
. "$here/../socketcan/bus_waits.sh"
bin=$(dirname "$CDCR_RUNTIME")
drive_sim=$here/../../tools/sim/cia402/drive_sim.js
image=$work/model.img
config=$work/drives.json
rate=20
# From the runtime's start to "drives: operational" (its own clock): about
# 4.5 s in the guest, most of it the SDO configuration of 16 drives.
operational_limit_ms=30000

"$CDCR_CHECK" image "$image" || fail "cannot write the model image"
"$CDCR_CHECK" pose-targets "$image" > "$work/targets.txt" || fail "cannot compute the targets"

for n in 1 2 3 4; do
  ip link add dev "vcan$n" type vcan && ip link set "vcan$n" txqueuelen 10000 && ip link set up "vcan$n" ||
    fail "cannot add vcan$n"
done

# Cable i = 4 s + k on bus s, node k + 1. Directions, scales and homing
# offsets differ from cable to cable so that a conversion that mixes them up
# shows (the pose depends on a segment's cable differences only, so an
# offset common to all would not). The drives power up on the straight robot:
# every cable 120 mm, the prototype's segment length.
initial_counts=2000,-1000,0,800  # (120 - homing_offset_mm) * counts_per_mm * direction
# write_config FILE BOOT_TIMEOUT_MS
write_config() {
{
  echo '{"buses": ["vcan1", "vcan2", "vcan3", "vcan4"], "heartbeat_ms": 100, "heartbeat_periods_lost": 20,'
  echo " \"stale_cycles\": 20, \"sync_window_us\": 20000, \"boot_timeout_ms\": $2, \"sdo_timeout_ms\": 2000,"
  echo ' "enable_timeout_ms": 10000, "max_speed_mm_per_s": 20, "drives": ['
  i=0
  while [ "$i" -lt 16 ]; do
    [ $((i % 2)) -eq 0 ] && direction=1 || direction=-1
    [ $((i % 4)) -lt 2 ] && counts=1000 || counts=800
    [ "$i" -lt 15 ] && comma=, || comma=
    echo "  {\"cable\": $i, \"bus\": $((i / 4)), \"node\": $((i % 4 + 1)), \"counts_per_mm\": $counts,"
    echo "   \"direction\": $direction, \"homing_offset_mm\": $((118 + i % 4)).0}$comma"
    i=$((i + 1))
  done
  echo ']}'
} > "$1"
}
write_config "$config" 20000
# The heartbeat is slow on purpose: the manager faults a drive whose heartbeat
# says pre-operational once it has sent the NMT start (nmt_left), and in the
# guest one the drive sent just before it saw the start can arrive after it.
# A long period makes that rare; it is the manager's race, not the drives'.

# start_sims RUN OPTIONS_1 OPTIONS_2 OPTIONS_3 OPTIONS_4: a node process
# per bus, with the options (faults) given for the one on vcan1..vcan4;
# their pids in sim_1..sim_4. Each run's logs: drive_sim.RUN.N.err.
start_sims() {
  run=$1
  shift
  sims=""
  for n in 1 2 3 4; do
    options=$1
    shift
    # shellcheck disable=SC2086  # the options' words
    node "$drive_sim" --can "vcan$n" --nodes 1,2,3,4 --relay "$bin/cdcr-can-relay" --initial-counts "$initial_counts" \
      $options 2> "$work/drive_sim.$run.$n.err" &
    sims="$sims $!"
    eval "sim_$n=$!"
  done
  sims_up() { [ "$(cat "$work"/drive_sim."$run".*.err | grep -c 'drive(s) on vcan')" -ge 4 ]; }
  wait_until "the drive simulators" sims_up
}
stop_sims() {
  # shellcheck disable=SC2086
  kill $sims 2>/dev/null
  # shellcheck disable=SC2086
  wait $sims 2>/dev/null
  sims=""
}
sims=""
stop_all() {
  [ -n "${runtime_pid:-}" ] && kill -INT "$runtime_pid" 2>/dev/null && wait "$runtime_pid"
  stop_sims
}
trap stop_all EXIT

# The drives first: they must answer the NMT reset of the runtime's first
# cycle. The faults wait for a SIGUSR2 each (drive_sim.js --fault ...@usr2):
# drive 2 of vcan2 will stop its heartbeat, drive 3 of vcan3 send an EMCY.
start_sims main "" "--fault heartbeat-stop:2@usr2" "--fault emcy:3:2310@usr2" ""
progress "16 drives up"

"$CDCR_RUNTIME" --can vcan0 --drives cia402 --drives-config "$config" --image "$image" --rate "$rate" --seconds 0 \
  > "$work/runtime.out" 2> "$work/runtime.err" &
runtime_pid=$!
# shellcheck disable=SC2034  # bus_waits.sh's wait_until reads it
wait_seconds=$((operational_limit_ms / 1000 + 30))
operational() { grep -q '^drives: \(operational\|fault\) after' "$work/runtime.err"; }
wait_until "drives: operational" operational
grep -q '^drives: fault after' "$work/runtime.err" && fail "before operational: $(grep '^drives: fault' "$work/runtime.err")"
operational_ms=$(sed -n 's/^drives: operational after \([0-9]*\) ms$/\1/p' "$work/runtime.err")
[ -n "$operational_ms" ] && [ "$operational_ms" -le "$operational_limit_ms" ] ||
  fail "drives: operational after ${operational_ms:-?} ms, the limit is $operational_limit_ms ms"
progress "drives: operational after $operational_ms ms (limit $operational_limit_ms ms)"

peer_config=$config
peer() { /usr/bin/python3 "$here/uml_host_peer.py" "$@" --dbc "$CDCR_EXTRA" --config "$peer_config"; }
peer targets --targets "$work/targets.txt" --cables "$work/still_cables.csv" --poses "$work/still_poses.txt" ||
  fail "the six pose targets"
progress "six pose targets reached"

# shellcheck disable=SC2154  # sim_3, sim_2: set by eval above
kill -USR2 "$sim_3"
peer fault --code 14 --node 3 --recover || fail "drive 3 on vcan3: EMCY and recovery"
grep -q '^fault: emergency, drive 3 (cable 10), detail 8976$' "$work/runtime.err" ||
  fail "no console line for drive 3's EMCY"
progress "EMCY of drive 3 reported and recovered"
kill -USR2 "$sim_2"
peer fault --code 13 --node 2 || fail "drive 2 on vcan2: heartbeat stopped"
grep -q '^fault: heartbeat lost, drive 2 (cable 5)' "$work/runtime.err" ||
  fail "no console line for drive 2's heartbeat"
progress "heartbeat loss of drive 2 reported"

kill -INT "$runtime_pid"
wait "$runtime_pid"
runtime_status=$?
runtime_pid=""
echo "--- cdcr-runtime"
cat "$work/runtime.err" "$work/runtime.out"
[ "$runtime_status" -eq 0 ] || fail "cdcr-runtime exited with $runtime_status after SIGINT"
# The two injected faults, and no other.
unexpected=$(grep '^fault: ' "$work/runtime.err" | grep -v '^fault: emergency, drive 3 (cable 10)' |
  grep -v '^fault: heartbeat lost, drive 2 (cable 5)')
[ -z "$unexpected" ] || fail "faults not injected: $unexpected"

"$CDCR_RUNTIME" --replay "$work/still_cables.csv" --image "$image" --out "$work/replay.csv" || fail "the replay"
/usr/bin/python3 "$here/uml_host_peer.py" compare --poses "$work/still_poses.txt" --replay "$work/replay.csv" ||
  fail "the still poses against the replay"
stop_sims

# Faults at start-up, each a run of its own from power-up with a shorter
# boot timeout: a drive that refuses a configuration write (the SDO abort
# of a read-only object) and one that never answers. STATUS must name each
# with the drive's node, and the console the drive and its cable.
write_config "$work/drives_short_boot.json" 3000
peer_config=$work/drives_short_boot.json
# startup_fault RUN BUS FAULT CODE NODE CONSOLE_LINE
startup_fault() {
  case $2 in
    1) start_sims "$1" "$3" "" "" "" ;;
    2) start_sims "$1" "" "$3" "" "" ;;
    3) start_sims "$1" "" "" "$3" "" ;;
    *) start_sims "$1" "" "" "" "$3" ;;
  esac
  "$CDCR_RUNTIME" --can vcan0 --drives cia402 --drives-config "$peer_config" --image "$image" --rate "$rate" \
    --seconds 0 > "$work/runtime.$1.out" 2> "$work/runtime.$1.err" &
  runtime_pid=$!
  peer fault --code "$4" --node "$5" || fail "$1: STATUS FAULT $4 with FAULT_DETAIL $5"
  kill -INT "$runtime_pid"
  wait "$runtime_pid"
  runtime_pid=""
  stop_sims
  grep "^fault: " "$work/runtime.$1.err"
  grep -q "^fault: $6" "$work/runtime.$1.err" || fail "$1: no console line 'fault: $6'"
  progress "$1: STATUS FAULT $4, FAULT_DETAIL $5"
}
startup_fault refused 2 "--fault refuse:2:6060" 15 2 "configuration write refused, drive 2 (cable 5), detail 100728834"
startup_fault silent 4 "--fault silent:3" 13 3 "no boot-up message, drive 3 (cable 14)"
progress "all done"
echo "SOCKETCAN_TEST_PASS"
