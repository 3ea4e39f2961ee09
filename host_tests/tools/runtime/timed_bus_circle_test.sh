#!/usr/bin/env bash
# The streamed circle on a timed bus (cdcr-runtime --sim --bitrate): the
# paper's robot at 1 kHz streaming on one classical 1 Mbit/s bus is refused
# before it runs, with its budget; at 250 Hz with radii every 5 cycles it
# fits (51.3 % worst case) and runs in closed loop with every frame on the
# wire for its time: none late for its cycle, the measured load between the
# budget's load without a stuff bit and its worst case, setpoints in every
# streamed cycle after the first 3 and the following error within the
# demo's bounds. The same with the identifiers moved to 0x300 (--id-base):
# every frame on 0x300 to 0x37F and the same figures. At 1 kHz the same
# holds on one CAN FD bus (60.1 % worst case) and on two FD buses, the
# drives' traffic on one (57.5 %) and the host's on the other (50.4 %).
#
#   timed_bus_circle_test.sh CDCR_RUNTIME MODEL_IMAGE
set -euo pipefail
runtime=$1 image=$2
fail() {
  echo "timed bus circle: $*" >&2
  exit 1
}

set +e
refused=$("$runtime" --image "$image" --sim --circle --bitrate 1000000 2>&1 >/dev/null)
status=$?
set -e
echo "$refused"
[[ $status -eq 1 ]] || fail "1 kHz streaming on 1 Mbit/s exited $status, expected 1"
[[ $(wc -l <<<"$refused") -eq 1 ]] || fail "the refusal is not one line"
[[ $refused == "cdcr-runtime: error: the CAN bus would carry up to 215.1 % of its time"* ]] ||
  fail "the refusal does not give the load"

# The figures of one bus's report line ("bus at ...", "host's bus at ...",
# "drives' bus at ..."): every frame on time, the measured load within the
# budget's bounds, the identifiers within [low, high].
check_bus() {
  local name=$1 label=$2 low=$3 high=$4
  line=$(grep "^${label} at [0-9]* bit/s.*: measured load" <<<"$out" || true)
  [[ -n $line ]] || fail "$name: no figures of the $label"
  read -r measured worst unstuffed first last late < <(sed -n \
    's/.*: measured load \([0-9.]*\) % .*worst case \([0-9.]*\) %, without stuffing \([0-9.]*\) %), [0-9]* frames on identifiers \(0x[0-9A-F]*\) to \(0x[0-9A-F]*\), \([0-9]*\) late.*/\1 \2 \3 \4 \5 \6/p' \
    <<<"$line")
  [[ -n ${late:-} ]] || fail "$name: the $label's line does not parse: $line"
  (( first >= low && last <= high )) || fail "$name: the $label's frames on $first to $last, outside $low to $high"
  verdict=$(awk -v m="$measured" -v w="$worst" -v u="$unstuffed" -v late="$late" 'BEGIN {
    if (late + 0 > 0) { print late " frames late for their cycle"; exit }
    if (m + 0 < u + 0 || m + 0 > w + 0) { print "measured load " m " % outside [" u ", " w "] %"; exit }
    if (w + 0 > 70) { print "worst case " w " % above the 70 % limit"; exit }
    print "ok"
  }')
  [[ $verdict == ok ]] || fail "$name, $label: $verdict"
}

# The circle in closed loop: setpoints in every streamed cycle after the
# first 3, the following error within the demo's bounds, no frame the
# protocol does not know.
check_circle() {
  local name=$1
  ! grep -q "not the protocol's" <<<"$out" || fail "$name: frames the protocol does not know"
  grep -q "^state RUN, fault: none" <<<"$out" || fail "$name: the runtime did not run without a fault"
  missed=$(sed -n 's/^setpoints sent in .* (none in \([0-9]*\) after the first 3).*/\1/p' <<<"$out")
  read -r mean max < <(sed -n 's/.*of which following.*: mean \([0-9.]*\) mm, max \([0-9.]*\) mm.*/\1 \2/p' <<<"$out")
  verdict=$(awk -v missed="${missed:-x}" -v mean="${mean:-x}" -v max="${max:-x}" 'BEGIN {
    if (missed == "x" || missed + 0 > 0) { print "streamed cycles without setpoints: " missed; exit }
    if (max == "x" || mean + 0 > 0.01 || max + 0 > 0.05) { print "following error mean " mean ", max " max " mm"; exit }
    print "ok"
  }')
  echo "timed bus circle, $name: $verdict"
  [[ $verdict == ok ]] || fail "$name: $verdict"
}

run() {
  out=$("$runtime" --image "$image" --sim --circle "$@")
  echo "$out"
}

# One classical bus at 250 Hz, radii every 5 cycles, at both bases.
for base in 0x100 0x300; do
  run --bitrate 1000000 --rate 250 --uncertainty-every 5 --id-base "$base"
  check_bus "classical, identifiers from $base" "bus" "$base" "$(printf '0x%X' $((base + 0x7F)))"
  check_circle "classical at 250 Hz, identifiers from $base"
done

# The paper's robot streaming at 1 kHz: on one CAN FD bus (1 Mbit/s, data
# at 5 Mbit/s), and on two (the drives on their own, 1 and 2 Mbit/s).
run --bitrate 1000000 --can-format fd-brs --data-bitrate 5000000
grep -q "CAN FD at 1 Mbit/s, data at 5 Mbit/s" <<<"$out" || fail "one FD bus: the budget does not name the format"
grep -q "^bus at 1000000 bit/s, data 5000000 bit/s (CAN FD): measured" <<<"$out" ||
  fail "one FD bus: the bus's figures do not name its rates and format"
check_bus "one FD bus at 1 kHz" "bus" 0x100 0x17F
check_circle "one FD bus at 1 kHz"

run --bitrate 1000000 --can-format fd-brs --data-bitrate 2000000 --drives-bus
check_bus "two FD buses at 1 kHz" "host's bus" 0x120 0x17F
check_bus "two FD buses at 1 kHz" "drives' bus" 0x100 0x11F
check_circle "two FD buses at 1 kHz"
