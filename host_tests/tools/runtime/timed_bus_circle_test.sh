#!/usr/bin/env bash
# The streamed circle on a timed bus (cdcr-runtime --sim --bitrate): the
# paper's robot at 1 kHz streaming on one classical 1 Mbit/s bus is refused
# before it runs, with its budget; at 250 Hz with radii every 5 cycles it
# fits (51.3 % worst case) and runs in closed loop with every frame on the
# wire for its time: none late for its cycle, the measured load between the
# budget's load without a stuff bit and its worst case, setpoints in every
# streamed cycle after the first 3 and the following error within the
# demo's bounds. The same with the identifiers moved to 0x300 (--id-base):
# every frame on 0x300 to 0x37F and the same figures.
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

check_run() {
  local base=$1 low=$2 high=$3
  out=$("$runtime" --image "$image" --sim --circle --bitrate 1000000 --rate 250 --uncertainty-every 5 --id-base "$base")
  echo "$out"
  read -r measured worst unstuffed first last late < <(sed -n \
    's/^bus at 1000000 bit\/s: measured load \([0-9.]*\) % .*worst case \([0-9.]*\) %, without stuffing \([0-9.]*\) %), [0-9]* frames on identifiers \(0x[0-9A-F]*\) to \(0x[0-9A-F]*\), \([0-9]*\) late.*/\1 \2 \3 \4 \5 \6/p' \
    <<<"$out")
  [[ -n ${late:-} ]] || fail "no bus figures in the output"
  (( first >= low && last <= high )) || fail "base $base: frames on $first to $last, outside $low to $high"
  ! grep -q "not the protocol's" <<<"$out" || fail "base $base: frames the protocol does not know"
  missed=$(sed -n 's/^setpoints sent in .* (none in \([0-9]*\) after the first 3).*/\1/p' <<<"$out")
  read -r mean max < <(sed -n 's/.*of which following.*: mean \([0-9.]*\) mm, max \([0-9.]*\) mm.*/\1 \2/p' <<<"$out")
  verdict=$(awk -v m="$measured" -v w="$worst" -v u="$unstuffed" -v late="$late" -v missed="${missed:-x}" \
    -v mean="${mean:-x}" -v max="${max:-x}" 'BEGIN {
    if (late + 0 > 0) { print late " frames late for their cycle"; exit }
    if (m + 0 < u + 0 || m + 0 > w + 0) { print "measured load " m " % outside [" u ", " w "] %"; exit }
    if (missed == "x" || missed + 0 > 0) { print "streamed cycles without setpoints: " missed; exit }
    if (max == "x" || mean + 0 > 0.01 || max + 0 > 0.05) { print "following error mean " mean ", max " max " mm"; exit }
    print "ok"
  }')
  echo "timed bus circle, identifiers from $base: $verdict"
  [[ $verdict == ok ]]
}
check_run 0x100 0x100 0x17F
check_run 0x300 0x300 0x37F
