# Sourced by bus_test.sh, deploy_test.sh and the deploy bench's guest script:
# waiting for what the runtime sent, sending, the capture's markers, and the
# simulated drives, inside the guest. Needs `log` (the candump capture,
# line-buffered), `work` and `capture_dir`, and sets `wait_seconds` from
# CDCR_WAIT_SECONDS (60): how long one wait may take before the test fails.
wait_seconds=${CDCR_WAIT_SECONDS:-60}

# The deploy scripts' places: CDCR_WORK_DIR, the capture on a tmpfs of its
# own, and the runtime's flash folder. Sets work, capture_dir, log, flash.
prepare_deploy_work() {
  work=$CDCR_WORK_DIR
  capture_dir=$work/capture
  mkdir -p "$capture_dir"
  mount -t tmpfs tmpfs "$capture_dir" || exit 1
  log=$capture_dir/candump.log
  flash=$work/flash
}

# The drives: one cangen per segment sending its FEEDBACK_<segment> frame
# (from socketcan_check frames) every feeder_gap_ms (10 unless set), at
# identifiers <feeder_id_prefix><segment> (10: the protocol's default base).
feeders=""
start_feeders() {
  feeders=""
  segment=0
  while [ "$segment" -lt "$SEGMENTS" ]; do
    data=""
    eval "data=\$FEEDBACK_$segment"
    cangen vcan0 -I "${feeder_id_prefix:-10}$segment" -L 8 -D "$data" -g "${feeder_gap_ms:-10}" &
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

# Frames the guest's receive backlog dropped (for every listener at once).
report_drops() {
  dropped_total=0
  while read -r _ dropped _; do
    dropped_total=$((dropped_total + 0x$dropped))
  done < /proc/net/softnet_stat
  echo "bus_test: frames dropped by the receive backlog: $dropped_total; cansend retries: ${send_retries:-0}"
}

fail() {
  report_drops
  echo "SOCKETCAN_TEST_FAIL: $*"
  cp "$log" "$work/candump.log" 2>/dev/null
  exit 1
}

# Seconds since boot into now_s, without starting a process (each costs
# tens of milliseconds in the guest).
now() {
  read -r now_s _ < /proc/uptime
  now_s=${now_s%.*}
}
now
started_s=$now_s
progress() {
  now
  echo "bus_test: $1 after $((now_s - started_s)) s"
}

# wait_until <what> <condition...>: runs the condition until it succeeds;
# fails the test after wait_seconds.
wait_until() {
  what=$1
  shift
  now
  wait_start_s=$now_s
  deadline=$((now_s + wait_seconds))
  until "$@"; do
    now
    [ "$now_s" -lt "$deadline" ] || fail "timed out after $wait_seconds s waiting for $what"
    sleep 0.5
  done
  # Long waits are what a busy host costs; the log shows where.
  now
  [ $((now_s - wait_start_s)) -lt 3 ] || echo "bus_test: waited $((now_s - wait_start_s)) s for $what"
}

# send <frame>: cansend, again while the transmit queue is full (ENOBUFS,
# when the guest falls behind the feeders), for a few seconds at most.
send_retries=0
send() {
  tries=0
  until cansend vcan0 "$1" 2> "$capture_dir/cansend.err"; do
    tries=$((tries + 1))
    send_retries=$((send_retries + 1))
    [ "$tries" -le 100 ] || fail "cansend $1: $(cat "$capture_dir/cansend.err")"
    sleep 0.05
  done
}

# Conditions on the capture. A frame is matched by a pattern at the start of
# its candump text ("150#01": a STATUS in RUN). Each check is one tail and one
# awk: starting a process costs tens of milliseconds of the guest's CPU, and
# the capture grows by hundreds of lines a second, so a phase is read from
# where its marker was sent, not from the start.
# marker <n>: notes the capture's size, then sends the marker.
marker() {
  eval "marker_offset_$1=\$(($(stat -c %s "$log") + 1))"
  send "7F0#$1"
}
# in_phase <marker> <awk arguments...>: awk over the capture from the marker
# on; the program sees the marker's frame as `marker`.
in_phase() {
  eval "offset=\${marker_offset_$1:-1}"
  phase_marker="7F0#$1"
  shift
  tail -c "+$offset" "$log" | awk -v marker="$phase_marker" "$@"
}
# marker_seen <marker>: the marker itself is in the capture.
marker_seen() { in_phase "$1" '$3 == marker { found = 1; exit } END { exit !found }'; }
# seen <marker> <frame>: the frame follows the marker.
seen() {
  in_phase "$1" -v frame="^$2" '
    $3 == marker { after = 1; next }
    after && $3 ~ frame { found = 1; exit }
    END { exit !found }'
}
# count <marker> <frame>: how many such frames follow the marker.
count() {
  in_phase "$1" -v frame="^$2" '
    $3 == marker { after = 1; next }
    after && $3 ~ frame { n++ }
    END { print n + 0 }'
}
# seen_count <marker> <frame> <at least>
seen_count() { [ "$(count "$1" "$2")" -ge "$3" ]; }
# seen_after <marker> <frame> <later frame>: the later frame follows the
# first such frame after the marker.
seen_after() {
  in_phase "$1" -v frame="^$2" -v later="^$3" '
    $3 == marker { after = 1; next }
    after && !first && $3 ~ frame { first = 1; next }
    first && $3 ~ later { found = 1; exit }
    END { exit !found }'
}
# The runtime's latest STATUS says RUN (it comes every 10 cycles, far more
# often than the last 16 KB of the capture).
in_run() { tail -c 16384 "$log" | awk '$3 ~ /^150#/ { last = $3 } END { exit last !~ /^150#01/ }'; }
