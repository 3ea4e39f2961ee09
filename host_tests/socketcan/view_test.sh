#!/bin/sh
# The view test, run inside the guest on vcan0: `cdcr view` listening to
# cdcr-runtime and the drives (one cangen per segment).
#   1. The view alone on a quiet bus sends nothing.
#   2. With the runtime in RUN, it records the bus for 5 s; the host then
#      reads the recording with @mcap/core and checks every message against
#      cdcr-runtime --replay of the cables it saw (view_on_vcan.sh).
#   CDCR_RUNTIME, CDCR_CLI, CDCR_CHECK: host-built binaries; CDCR_WORK_DIR.
set -u
. "$(dirname "$0")/bus_waits.sh"
prepare_deploy_work
image=$work/model.img
rm -f "$work/view.mcap" "$work"/view-*.out "$work"/view-*.err "$work/runtime.err"

"$CDCR_CHECK" image "$image" || fail "cannot write the model image"
eval "$("$CDCR_CHECK" frames "$image")" || fail "cannot compute the frames"
stdbuf -oL candump -L -r 4194304 vcan0 > "$log" &
candump_pid=$!
sleep 0.5

# 1. Alone: every frame on the bus would be the view's.
"$CDCR_CLI" view --can vcan0 --image "$image" --port 0 --seconds 2 > "$work/view-alone.out" 2> "$work/view-alone.err" ||
  fail "cdcr view alone: $(cat "$work/view-alone.err")"
sleep 0.2
[ ! -s "$log" ] || fail "frames on the bus with only the view on it: $(head -n 3 "$log")"
progress "the view alone sent nothing: $(cat "$work/view-alone.out")"

# 2. Beside the runtime and the drives.
start_feeders
"$CDCR_RUNTIME" --image "$image" --can vcan0 --rate 100 > /dev/null 2> "$work/runtime.err" &
runtime_pid=$!
wait_until "the runtime in RUN" in_run
"$CDCR_CLI" view --can vcan0 --image "$image" --port 0 --seconds 5 --record "$work/view.mcap" \
  > "$work/view-run.out" 2> "$work/view-run.err" || fail "cdcr view: $(cat "$work/view-run.err")"
progress "$(tr '\n' ' ' < "$work/view-run.out")"
[ -s "$work/view.mcap" ] || fail "no recording"
kill "$runtime_pid" "$candump_pid" 2>/dev/null
stop_feeders
wait 2>/dev/null
echo "SOCKETCAN_TEST_PASS"
