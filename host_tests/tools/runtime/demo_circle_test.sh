#!/usr/bin/env bash
# tools/demo.sh step 9 on the demo's model: `cdcr-runtime --sim --circle`,
# a TRACKING pose target every cycle around a 40 mm circle at 50 mm/s, the
# targets the model's own poses along it. Every streamed cycle after the
# first 3 must send setpoints, and the following error (the compensated
# model at the setpoints against the target) must stay at a mean of 0.01 mm
# and a maximum of 0.05 mm (0.005 and 0.013 measured).
#
#   demo_circle_test.sh CDCR_RUNTIME MODEL_IMAGE
set -euo pipefail
runtime=$1 image=$2

out=$("$runtime" --image "$image" --sim --circle --circle-radius 40 --circle-speed 50)
echo "$out"
missed=$(sed -n 's/^setpoints sent in .* (none in \([0-9]*\) after the first 3).*/\1/p' <<<"$out")
read -r mean max < <(sed -n 's/.*of which following.*: mean \([0-9.]*\) mm, max \([0-9.]*\) mm.*/\1 \2/p' <<<"$out")
verdict=$(awk -v missed="${missed:-}" -v mean="${mean:-}" -v max="${max:-}" 'BEGIN {
  if (missed == "" || mean == "") { print "no figures in the output"; exit }
  if (missed + 0 > 0) { print missed " streamed cycles after the first 3 sent no setpoints"; exit }
  if (mean + 0 > 0.01) { print "following error mean " mean " mm above 0.01 mm"; exit }
  if (max + 0 > 0.05) { print "following error max " max " mm above 0.05 mm"; exit }
  print "ok"
}')
echo "demo circle: $verdict"
[[ $verdict == ok ]]
