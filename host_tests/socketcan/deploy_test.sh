#!/bin/sh
# The deploy test, run inside the guest on vcan0: `cdcr deploy` sends new
# models to `cdcr-runtime --flash-dir` while the drives' cable frames flow.
#   1. A new model reaches the runtime; poses keep coming during the
#      transfer and change to the new model's values after the commit.
#   2. A larger model, with the runtime killed (SIGKILL) at 10 random moments
#      of the transfer and restarted each time on the same flash: every
#      restart runs a valid image, and the deploy resumes and finishes.
#   3. A model through a faulty link: `cdcr deploy` on vcan1, the runtime on
#      vcan0 at 25 Hz (the pace of the busy machine where deploys were
#      refused as malformed: 36 ms a cycle, so that the sender's 200 ms of
#      silence before it STARTs again are a few cycles), and between them
#      socketcan_relay (beside CDCR_CHECK), which loses 5 % of the frames
#      each way and repeats and reorders 1 % (seeded): the transfer resends
#      and commits.
#   4. The protocol moved to identifiers from 0x300 (--id-base): the drives'
#      frames there bring the runtime to RUN while the old ones at 0x100
#      still flow, foreign now; a deploy at the same base reaches it and one
#      at the default base does not.
#   CDCR_RUNTIME, CDCR_CLI, CDCR_CHECK: host-built binaries; CDCR_WORK_DIR.
set -u
. "$(dirname "$0")/bus_waits.sh"
prepare_deploy_work
rm -rf "$flash" "$work"/runtime.err.* "$work"/deploy.* "$work"/relay.err

"$CDCR_CHECK" image "$work/old.img" 24 1 || fail "cannot write the old image"
"$CDCR_CHECK" image "$work/new.img" 40 2 || fail "cannot write the new image"
"$CDCR_CHECK" image "$work/big.img" 1000 3 || fail "cannot write the large image"
"$CDCR_CHECK" image "$work/lossy.img" 100 4 || fail "cannot write the image for the faulty link"
eval "$("$CDCR_CHECK" frames "$work/old.img")" || fail "cannot compute the frames"

start_feeders
stdbuf -oL candump -L -r 4194304 vcan0,130:7F8,150:7FF,178:7FF,7F0:7FF,350:7FF > "$log" &
candump_pid=$!

restarts=0
rate=100
start_runtime() {
  "$CDCR_RUNTIME" --image "$work/old.img" --can vcan0 --flash-dir "$flash" --rate "$rate" \
    > /dev/null 2> "$work/runtime.err.$restarts" &
  runtime_pid=$!
}
stop_all() {
  kill "$runtime_pid" $feeders "$candump_pid" 2>/dev/null
  wait 2>/dev/null
}
start_runtime
wait_until "the runtime in RUN" in_run
progress "runtime up on the old model"

# 1. A deploy while poses flow.
marker 01
wait_until "poses on the old model" seen_count 01 "130#" 5
pose_before=$(in_phase 01 '$3 ~ /^130#/ { print $3; exit }')
"$CDCR_CLI" deploy --can vcan0 --image "$work/new.img" --quiet > "$work/deploy.out" 2> "$work/deploy.err" ||
  fail "deploy: $(cat "$work/deploy.err")"
marker 02
progress "$(cat "$work/deploy.out")"
wait_until "poses on the new model" seen_count 02 "130#" 5
pose_after=$(in_phase 02 '$3 ~ /^130#/ { last = $3 } END { print last }')
[ "$pose_before" != "$pose_after" ] || fail "the pose did not change with the new model ($pose_after)"
# Poses every cycle (100 Hz) during the transfer: no gap of more than
# 0.5 s, a generous bound for the guest, and none missing around the switch.
gap=$(in_phase 01 '
  $3 == marker { after = 1; next }
  after && $3 ~ /^7F0#/ { exit }
  after && $3 ~ /^131#/ { t = substr($1, 2, length($1) - 2) + 0; if (last && t - last > max) max = t - last; last = t; n++ }
  END { printf "%d %.3f\n", n, max }')
progress "poses during the transfer and max gap (s): $gap"
echo "$gap" | awk '{ exit !($1 >= 10 && $2 < 0.5) }' || fail "poses stalled during the transfer: $gap"
"$CDCR_CLI" deploy --can vcan0 --status > "$work/deploy.status" 2>&1 || fail "status: $(cat "$work/deploy.status")"
grep -q "active slot A" "$work/deploy.status" || fail "status: $(cat "$work/deploy.status")"
progress "$(cat "$work/deploy.status")"

# 2. SIGKILL at 10 random moments of a transfer.
"$CDCR_CLI" deploy --can vcan0 --image "$work/big.img" --quiet --timeout 120 \
  > "$work/deploy.big.out" 2> "$work/deploy.big.err" &
deploy_pid=$!
while [ "$restarts" -lt 10 ]; do
  pause=$(awk -v seed="$restarts$$" 'BEGIN { srand(seed); printf "%.2f", 0.2 + rand() * 0.8 }')
  sleep "$pause"
  kill -0 "$deploy_pid" 2>/dev/null || fail "the deploy ended before kill $((restarts + 1)): $(cat "$work/deploy.big.err")"
  kill -KILL "$runtime_pid"
  wait "$runtime_pid" 2>/dev/null
  restarts=$((restarts + 1))
  start_runtime
  wait_until "restart $restarts in RUN on a valid image" grep -q "state RUN" "$work/runtime.err.$restarts"
  if grep -q "fault" "$work/runtime.err.$restarts"; then
    fail "restart $restarts: $(cat "$work/runtime.err.$restarts")"
  fi
  progress "kill $restarts after $pause s: restarted in RUN"
done
wait "$deploy_pid" || fail "deploy after 10 kills: $(cat "$work/deploy.big.err")"
progress "$(cat "$work/deploy.big.out")"
"$CDCR_CLI" deploy --can vcan0 --status > "$work/deploy.status" 2>&1 || fail "status: $(cat "$work/deploy.status")"
grep -q "active slot B" "$work/deploy.status" || fail "status after the large model: $(cat "$work/deploy.status")"

# 3. Through a faulty link, to the runtime at 25 Hz.
kill "$runtime_pid"
wait "$runtime_pid" 2>/dev/null
restarts=$((restarts + 1))
rate=25
start_runtime
wait_until "the runtime in RUN at 25 Hz" grep -q "state RUN" "$work/runtime.err.$restarts"
ip link add dev vcan1 type vcan && ip link set up vcan1 || fail "cannot bring up vcan1"
"$(dirname "$CDCR_CHECK")/socketcan_relay" vcan1 vcan0 0.05 0.01 0.01 24 2> "$work/relay.err" &
relay_pid=$!
"$CDCR_CLI" deploy --can vcan1 --image "$work/lossy.img" --quiet --timeout 60 \
  > "$work/deploy.lossy.out" 2> "$work/deploy.lossy.err"
deploy_status=$?
kill "$relay_pid"
wait "$relay_pid"
[ "$deploy_status" -eq 0 ] || fail "deploy through the faulty link: $(cat "$work/deploy.lossy.err"); relay: $(cat "$work/relay.err")"
progress "$(cat "$work/deploy.lossy.out"); relay: $(cat "$work/relay.err")"
"$CDCR_CLI" deploy --can vcan0 --status > "$work/deploy.status" 2>&1 || fail "status: $(cat "$work/deploy.status")"
grep -q "active slot A" "$work/deploy.status" || fail "status after the faulty link: $(cat "$work/deploy.status")"

# 4. Identifiers from 0x300.
kill "$runtime_pid"
wait "$runtime_pid" 2>/dev/null
default_feeders=$feeders
feeder_id_prefix=30 start_feeders
feeders="$feeders $default_feeders"
"$CDCR_RUNTIME" --image "$work/old.img" --can vcan0 --flash-dir "$flash" --rate 100 --id-base 0x300 \
  > /dev/null 2> "$work/runtime.err.base" &
runtime_pid=$!
in_run_at_0x300() { tail -c 16384 "$log" | awk '$3 ~ /^350#/ { last = $3 } END { exit last !~ /^350#01/ }'; }
wait_until "the runtime at 0x300 in RUN on the drives' frames at 0x300" in_run_at_0x300
if "$CDCR_CLI" deploy --can vcan0 --status --timeout 2 > "$work/deploy.status" 2>&1; then
  fail "a status request at the default base reached the runtime at 0x300: $(cat "$work/deploy.status")"
fi
"$CDCR_CLI" deploy --can vcan0 --id-base 0x300 --image "$work/new.img" --quiet > "$work/deploy.base.out" \
  2> "$work/deploy.base.err" || fail "deploy at 0x300: $(cat "$work/deploy.base.err")"
"$CDCR_CLI" deploy --can vcan0 --id-base 0x300 --status > "$work/deploy.status" 2>&1 ||
  fail "status at 0x300: $(cat "$work/deploy.status")"
grep -q "active slot B" "$work/deploy.status" || fail "status after the deploy at 0x300: $(cat "$work/deploy.status")"
progress "identifiers from 0x300: $(cat "$work/deploy.base.out"); $(cat "$work/deploy.status")"
stop_all
echo "SOCKETCAN_TEST_PASS"
exit 0
