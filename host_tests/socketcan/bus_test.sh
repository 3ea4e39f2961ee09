#!/bin/sh
# The bus test, run inside the guest on vcan0: cdcr-runtime against can-utils.
# Phases are separated by marker frames (7F0#<n>) so the checker can cut the
# candump log; see socketcan_check.cpp for what each phase must show.
#   CDCR_RUNTIME, CDCR_CHECK: host-built binaries; CDCR_WORK_DIR: scratch space.
#   CDCR_WAIT_SECONDS: how long one wait may take before the test fails (60).
#
# Frames are checked strictly, time loosely. Inside User-Mode Linux, on a
# host that may be busy, the runtime does not hold its rate and its cable input
# turns stale now and then although the feeders keep sending. So the driver
# never sleeps a fixed time hoping something happened: it waits for what the
# checker will look for (a state in STATUS, so many poses, a STATS frame
# after an event), each wait with a generous deadline so that a hang still
# fails, and it sends again what the runtime refused in FAULT, as a planner
# would.
set -u
work=$CDCR_WORK_DIR
image=$work/model.img
# The capture lives on a guest tmpfs, line-buffered, so the driver can wait
# for what the runtime sent; it is copied next to the other outputs at the end.
capture_dir=$work/capture
mkdir -p "$capture_dir"
mount -t tmpfs tmpfs "$capture_dir" || exit 1
log=$capture_dir/candump.log
rm -f "$work/candump.log" "$work/runtime.out" "$work/runtime.err"

. "$(dirname "$0")/bus_waits.sh"

# Enough poses in a phase for the checker (it wants 20, or 10 after the
# random traffic), counted by their last frame.
poses_wanted=30

# The runtime's rate, and the drives' feedback period. Every system call is
# slow in the guest (about 0.1 ms): a cycle there costs one to three
# milliseconds of its one CPU, and every frame on the bus more, so at the
# board's 1 kHz the runtime and the feeders would take that CPU from each
# other and from this driver, the input would keep turning stale, and a busy
# host would stretch the test to many minutes. What is checked here does not
# depend on the rate (the host's runtime tests check the cycle in lockstep
# time). The feeders send every 10 ms, a tenth of the stale limit (10
# cycles) at 100 Hz.
runtime_rate_hz=100
feeder_gap_ms=10

"$CDCR_CHECK" image "$image" || fail "cannot write the model image"
eval "$("$CDCR_CHECK" frames "$image")" || fail "cannot compute the frames"

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
progress "command-line checks done"

# A large receive buffer: candump must not lose the markers under load.
stdbuf -oL candump -L -r 4194304 vcan0 > "$log" &
candump_pid=$!
"$CDCR_RUNTIME" --image "$image" --can vcan0 --rate "$runtime_rate_hz" > "$work/runtime.out" 2> "$work/runtime.err" &
runtime_pid=$!
# Both are up once the capture holds the runtime's first STATUS.
wait_until "the first STATUS from cdcr-runtime" grep -q " 150#" "$log"
marker 00
wait_until "the runtime's STATUS without input" seen 00 150#0304

marker 01
start_feeders
wait_until "RUN with cable feedback" seen 01 150#01
wait_until "$poses_wanted poses with cable feedback" seen_count 01 132# "$poses_wanted"
progress "phase 1 (feedback) done"

marker 02
# Malformed frames until a STATUS reports the rejection (in FAULT, STATUS
# reports the stale input instead).
attempt=1
while :; do
  wait_until "RUN before the malformed frames" in_run
  send 100#0102                  # wrong DLC on a feedback frame
  send 101#01020304050607
  send 102#
  send 121#0000                  # wrong DLC on a target frame
  tries=0
  until seen 02 "150#0[0-2]0[57]" || [ "$tries" -ge 10 ]; do
    tries=$((tries + 1))
    sleep 0.5
  done
  seen 02 "150#0[0-2]0[57]" && break
  [ "$attempt" -lt 10 ] || fail "no STATUS reported the malformed frames in $attempt attempts"
  attempt=$((attempt + 1))
done
progress "phase 2 (malformed frames) done, attempt $attempt"

marker 03
# The runtime refuses a target while it is in FAULT (IK_REPORT outcome
# "rejected, state"); a planner waits for RUN and sends the target again, and
# so does this test, until the report says converged.
more_reports() { [ "$(count 03 140#05)" -gt "$reports_before" ]; }
attempt=1
while :; do
  wait_until "RUN before sending the target" in_run
  reports_before=$(count 03 140#05)
  send "121#$TARGET_XY"
  send "122#$TARGET_Z"
  wait_until "the IK_REPORT of attempt $attempt" more_reports
  seen 03 140#0500 && break
  [ "$attempt" -lt 20 ] || fail "the target did not converge in $attempt attempts"
  attempt=$((attempt + 1))
done
# The runtime sends the setpoints just before the report.
segment=0
while [ "$segment" -lt "$SEGMENTS" ]; do
  wait_until "the setpoint of segment $segment" seen 03 "11$segment#"
  segment=$((segment + 1))
done
progress "phase 3 (target) done, attempt $attempt"

# The feeders stop in phase 4, once a pose shows the runtime in RUN there, so
# that it turns stale (and counts it) after the marker; the checker allows a
# pose after a FAULT only while feedback still comes.
wait_until "RUN before the feeders stop" in_run
marker 04
wait_until "a pose before the feeders stop" seen 04 132#
stop_feeders
wait_until "FAULT, cable input stale" seen_after 04 132# 150#0304
wait_until "STATS after the FAULT" seen_after 04 150#0304 151#
progress "phase 4 (stale input) done"

marker 05
start_feeders
wait_until "RUN again" seen 05 150#01
wait_until "$poses_wanted poses after resuming" seen_count 05 132# "$poses_wanted"
progress "phase 5 (resume) done"

marker 06
cangen vcan0 -g 0.2 -n 300           # random identifiers, lengths and data
cangen vcan0 -I 102 -g 0.5 -n 100    # random lengths and data on a feedback id
# STATS from after the traffic, with every frame of it counted.
stats_wanted=$(($(count 06 151#) + 2))
wait_until "STATS after the random traffic" seen_count 06 151# "$stats_wanted"
wait_until "10 STATUS frames since the random traffic began" seen_count 06 150# 10
progress "phase 6 (random traffic) done"

marker 07
wait_until "RUN after the traffic" seen 07 150#01
wait_until "$poses_wanted poses after the traffic" seen_count 07 132# "$poses_wanted"
progress "phase 7 (after the traffic) done"

marker 08
# Pose targets one after another, each a pose of the model: every attempt
# must get exactly one final IK_REPORT and poses must keep coming while it
# is solved (the checker reads both from the capture). An attempt refused
# or aborted in FAULT is sent again under a new sequence number.
target=0
while [ "$target" -lt "$POSE_TARGETS" ]; do
  eval "orientation=\$POSE_TARGET_Q_$target position=\$POSE_TARGET_XY_$target"
  attempt=0
  while :; do
    [ "$attempt" -lt "$POSE_TARGET_ATTEMPTS" ] || fail "pose target $target did not converge in $attempt attempts"
    eval "commit=\$POSE_TARGET_Z_${target}_$attempt sequence=\$POSE_TARGET_SEQUENCE_${target}_$attempt"
    wait_until "RUN before pose target $target" in_run
    send "120#$orientation"
    send "121#$position"
    send "122#$commit"
    # A final report: any outcome but 06 (in progress).
    wait_until "the final IK_REPORT of pose target $target, attempt $attempt" seen 08 "140#${sequence}0[0-57-9A-F]"
    seen 08 "140#${sequence}00" && break
    attempt=$((attempt + 1))
  done
  target=$((target + 1))
done
progress "phase 8 (pose targets) done"

kill -INT "$runtime_pid"
wait "$runtime_pid"
runtime_status=$?
stop_feeders
marker FF
wait_until "the end of the capture" marker_seen FF
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
report_drops
progress "all done"
echo "SOCKETCAN_TEST_PASS"
