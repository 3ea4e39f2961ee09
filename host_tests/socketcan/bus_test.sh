#!/bin/sh
# The bus test, run inside the guest on vcan0: cdcr-runtime against can-utils.
# Phases are separated by marker frames (7F0#<n>) so the checker can cut the
# candump log; see socketcan_check.cpp for what each phase must show.
#   CDCR_RUNTIME, CDCR_CHECK: host-built binaries; CDCR_WORK_DIR: scratch space.
set -u
work=$CDCR_WORK_DIR
image=$work/model.img
# The capture lives on a guest tmpfs, line-buffered, so the driver can wait
# for what the runtime sent instead of guessing with sleeps (the host may be
# busy); it is copied next to the other outputs at the end.
capture_dir=$work/capture
mkdir -p "$capture_dir"
mount -t tmpfs tmpfs "$capture_dir" || exit 1
log=$capture_dir/candump.log
rm -f "$work/candump.log" "$work/runtime.out" "$work/runtime.err"

fail() {
  echo "SOCKETCAN_TEST_FAIL: $*"
  cp "$log" "$work/candump.log" 2>/dev/null
  exit 1
}

"$CDCR_CHECK" image "$image" || fail "cannot write the model image"
eval "$("$CDCR_CHECK" frames "$image")" || fail "cannot compute the frames"

marker() { cansend vcan0 "7F0#0$1"; }

# wait_for <marker byte> <frame prefix> <what>: until a frame starting with
# the prefix follows the marker in the capture, for a few seconds at most.
wait_for() {
  tries=0
  until sed -n "/ 7F0#$1\$/,\$p" "$log" | grep -q " $2"; do
    tries=$((tries + 1))
    [ "$tries" -le 100 ] || fail "timed out waiting for $3"
    sleep 0.05
  done
}

feeders=""
start_feeders() {
  feeders=""
  segment=0
  while [ "$segment" -lt "$SEGMENTS" ]; do
    data=""
    eval "data=\$FEEDBACK_$segment"
    cangen vcan0 -I "10$segment" -L 8 -D "$data" -g 2 &
    feeders="$feeders $!"
    segment=$((segment + 1))
  done
}
stop_feeders() {
  # shellcheck disable=SC2086
  kill $feeders 2>/dev/null
  # shellcheck disable=SC2086
  wait $feeders 2>/dev/null
  feeders=""
}

# A missing interface is one line and exit status 1.
"$CDCR_RUNTIME" --can vcan9 --seconds 0.1 > /dev/null 2> "$work/runtime.err"
missing_status=$?
if [ "$missing_status" -ne 1 ] || [ "$(wc -l < "$work/runtime.err")" -ne 1 ]; then
  fail "missing interface: status $missing_status, $(cat "$work/runtime.err")"
fi
# An image that does not parse still runs, DEGRADED.
head -c 100 /dev/zero > "$work/corrupt.img"
"$CDCR_RUNTIME" --image "$work/corrupt.img" --can vcan0 --seconds 0.2 > "$work/runtime.out" 2> "$work/runtime.err" ||
  fail "corrupt image: cdcr-runtime failed: $(cat "$work/runtime.err")"
grep -q "DEGRADED" "$work/runtime.err" || fail "corrupt image: not DEGRADED: $(cat "$work/runtime.err")"

# A large receive buffer: candump must not lose the markers under load.
stdbuf -oL candump -L -r 4194304 vcan0 > "$log" &
candump_pid=$!
"$CDCR_RUNTIME" --image "$image" --can vcan0 --rate 1000 > "$work/runtime.out" 2> "$work/runtime.err" &
runtime_pid=$!
# Both are up once the capture holds the runtime's first STATUS.
tries=0
until grep -q " 150#" "$log"; do
  tries=$((tries + 1))
  [ "$tries" -le 100 ] || fail "no STATUS from cdcr-runtime: $(cat "$work/runtime.err")"
  sleep 0.05
done
cansend vcan0 7F0#00
wait_for 00 150#0304 "the runtime's STATUS without input"

marker 1
start_feeders
wait_for 01 150#01 "RUN with cable feedback"
sleep 0.3

marker 2
cansend vcan0 100#0102               # wrong DLC on a feedback frame
cansend vcan0 101#01020304050607
cansend vcan0 102#
cansend vcan0 121#0000               # wrong DLC on a target frame
sleep 0.2

marker 3
# The runtime refuses a target while it is in FAULT (IK_REPORT outcome
# "rejected, state"), and here, where User-Mode Linux cannot hold 1 kHz, the
# feedback turns stale now and then; a planner sends the target again, and so
# does this test, until the report says converged or it has tried five times.
ik_reports() { sed -n "/ 7F0#03\$/,\$p" "$log" | grep -c " 140#05"; }
attempt=1
while :; do
  before=$(ik_reports)
  cansend vcan0 "121#$TARGET_XY"
  cansend vcan0 "122#$TARGET_Z"
  tries=0
  until [ "$(ik_reports)" -gt "$before" ]; do
    tries=$((tries + 1))
    [ "$tries" -le 100 ] || fail "timed out waiting for the IK_REPORT"
    sleep 0.05
  done
  sed -n "/ 7F0#03\$/,\$p" "$log" | grep -q " 140#0500" && break
  [ "$attempt" -lt 5 ] || break
  attempt=$((attempt + 1))
  sleep 0.1
done

marker 4
stop_feeders
wait_for 04 150#0304 "FAULT, cable input stale"

marker 5
start_feeders
wait_for 05 150#01 "RUN again"
sleep 0.3

marker 6
cangen vcan0 -g 0.2 -n 300           # random identifiers, lengths and data
cangen vcan0 -I 102 -g 0.5 -n 100    # random lengths and data on a feedback id
sleep 0.3

marker 7
wait_for 07 150#01 "RUN after the traffic"
sleep 0.2

kill -INT "$runtime_pid"
wait "$runtime_pid"
runtime_status=$?
stop_feeders
cansend vcan0 7F0#FF
wait_for FF 7F0#FF "the end of the capture"
kill "$candump_pid"
wait "$candump_pid" 2>/dev/null
cp "$log" "$work/candump.log"
umount "$capture_dir"
log=$work/candump.log

echo "--- cdcr-runtime"
cat "$work/runtime.err" "$work/runtime.out"
[ "$runtime_status" -eq 0 ] || fail "cdcr-runtime exited with $runtime_status after SIGINT"
grep -q "^cycles " "$work/runtime.out" || fail "cdcr-runtime printed no cycle statistics"
echo "--- checks ($(wc -l < "$log") frames logged)"
"$CDCR_CHECK" check "$image" "$log" || fail "bus checks"
echo "SOCKETCAN_TEST_PASS"
