#!/bin/sh
# view.mcap_recording: the demo's closed loop recorded (cdcr-runtime --sim
# --circle --record) and a replay's recording (--replay --record), each read
# by the reference MCAP reader and checked message by message against
# cdcr-runtime --replay (tools/view/clients/check_mcap.js); a replay's with a
# hysteresis image against the replay's own poses; and a recording that
# cannot be written is refused in one line and leaves no file.
#   recording_test.sh <node> <tools/view/clients> <cdcr-runtime> <cdcr> <image> <work dir>
set -eu
node=$1 clients=$2 runtime=$3 cdcr=$4 image=$5 work=$6
rm -rf "$work"
mkdir -p "$work"

"$runtime" --image "$image" --sim --circle --circle-radius 40 --circle-speed 50 --record "$work/circle.mcap" |
  grep -E "^(view|recording):"
"$node" "$clients/check_mcap.js" "$work/circle.mcap" --runtime "$runtime" --image "$image"

"$cdcr" simulate --samples 300 --seed 3 --session 2 --out "$work/rows.csv" >/dev/null
"$runtime" --image "$image" --replay "$work/rows.csv" --out "$work/poses.csv" --record "$work/replay.mcap"
"$node" "$clients/check_mcap.js" "$work/replay.mcap" --runtime "$runtime" --image "$image" --of-replay

# An image that tracks the cables' hysteresis, on a motion sequence with its
# homing move: the view's tracker (the board's, homed by the replay's HOMING
# frame) against the replay's own sequence of effective lengths, row by
# row. The lengths are rounded to what CABLE_FEEDBACK carries (0.01 mm), so
# both read the same numbers.
"$cdcr" simulate --hysteresis --samples 300 --seed 2 --out "$work/friction.csv" >/dev/null
"$cdcr" train --data "$work/friction.csv" --out "$work/friction.img" >/dev/null
"$cdcr" simulate --hysteresis --samples 200 --seed 2 --session 1 --out "$work/friction_rows.csv" >/dev/null
python3 - "$work/friction_rows.csv" "$work/friction_sent.csv" <<'PYTHON'
import sys

header = None
with open(sys.argv[1]) as rows, open(sys.argv[2], "w") as out:
    for line in rows:
        if line.startswith("#") or not line.strip():
            out.write(line)
        elif header is None:
            header = line.strip().split(",")
            out.write(line)
        else:
            fields = line.strip().split(",")
            out.write(",".join(f"{float(v):.2f}" if h.startswith("l") else v for h, v in zip(header, fields)) + "\n")
PYTHON
"$runtime" --image "$work/friction.img" --replay "$work/friction_sent.csv" --out "$work/friction_poses.csv" \
  --record "$work/friction.mcap"
"$node" "$clients/check_mcap.js" "$work/friction.mcap" --poses "$work/friction_poses.csv" --of-replay

if "$runtime" --image "$image" --sim --seconds 0.1 --record "$work/missing/x.mcap" >"$work/refused.txt" 2>&1; then
  echo "recording_test: a recording into a missing folder was not refused" >&2
  exit 1
fi
grep -q "^cdcr-runtime: error: cannot write $work/missing/x.mcap.tmp" "$work/refused.txt" || {
  echo "recording_test: unexpected refusal:" >&2
  cat "$work/refused.txt" >&2
  exit 1
}
echo "recording_test: $(cat "$work/refused.txt")"
