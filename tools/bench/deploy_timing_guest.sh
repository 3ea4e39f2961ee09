#!/bin/sh
# Inside the User-Mode Linux guest (run_deploy_bench.sh starts it): one
# timed `cdcr deploy` of $CDCR_WORK_DIR/deploy.img to `cdcr-runtime
# --flash-dir` on vcan0, the runtime asked for 1 kHz, with the drives'
# cable frames flowing; counts the update frames with candump.
set -u
. "$(dirname "$0")/../../host_tests/socketcan/bus_waits.sh"
prepare_deploy_work
rm -rf "$flash"
"$CDCR_CHECK" image "$work/old.img" 24 1 || fail "cannot write the old image"
eval "$("$CDCR_CHECK" frames "$work/old.img")" || fail "cannot compute the frames"
start_feeders
stdbuf -oL candump -L -r 4194304 vcan0,170:7F8,178:7FF > "$log" &
candump_pid=$!
"$CDCR_RUNTIME" --image "$work/old.img" --can vcan0 --flash-dir "$flash" --rate 1000 > /dev/null 2> "$work/runtime.err" &
runtime_pid=$!
sleep 5
read -r t0 _ < /proc/uptime
"$CDCR_CLI" deploy --can vcan0 --image "$work/deploy.img" --quiet --timeout 300 > "$work/deploy.out" 2> "$work/deploy.err" ||
  fail "deploy: $(cat "$work/deploy.err")"
read -r t1 _ < /proc/uptime
sleep 1
host_frames=$(grep -c " 17[0-3]#" "$log")
reports=$(grep -c " 178#" "$log")
progress "deploy of $(stat -c %s "$work/deploy.img") bytes from uptime $t0 s to $t1 s: $host_frames frames from the host, $reports reports; $(cat "$work/deploy.out")"
kill "$runtime_pid" $feeders "$candump_pid" 2>/dev/null
wait 2>/dev/null
echo "SOCKETCAN_TEST_PASS"
exit 0
