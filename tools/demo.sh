#!/usr/bin/env bash
# The main job end to end on the built-in simulated robot:
#   1-3. kinematics round trip on the paper's Table 1, case 2 (L = 120 mm,
#        r = 70 mm): cable lengths -> tip pose -> cable lengths -> same pose;
#   4.   a dataset from the simulated robot with the paper's protocol;
#   5.   GP training, held-out accuracy and the float32 flash image;
#   6.   the image checked and exported for a board;
#   7.   accuracy on an independent test set of the same robot;
#   8.   the firmware runtime with that image in closed loop with the
#        simulated robot over the simulated bus at 1 kHz;
#   9.   the same loop following a streamed circle (a TRACKING pose target
#        every cycle, 40 mm radius at 50 mm/s), recorded as the view sees it
#        on the bus (tools/view);
#   10.  the recording read back by the reference MCAP reader (@mcap/core),
#        every message checked, and how to open it.
# Everything it writes goes to build/demo/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

# view: Node.js and the MCAP reader that checks the recording of step 10.
bash tools/install-deps.sh base view

build_log=build/demo-build.log
mkdir -p build
echo "Building cdcr and cdcr-runtime (log: $build_log)"
if ! { cmake -S . -B build -DCMAKE_BUILD_TYPE=Release --log-level=WARNING &&
  cmake --build build -j"$(nproc)" --target cdcr cdcr-runtime; } >"$build_log" 2>&1; then
  tail -n 30 "$build_log" >&2
  echo "demo: build failed" >&2
  exit 1
fi

cdcr=build/bin/cdcr
geometry=(--length 120 --radius 70)
table1_case2_cables_mm=118,123,124,115,124,115,118,121,110,117,125,123,124,105,112,128

heading() {
  printf '\n== %s ==\n' "$1"
}

run() {
  echo "\$ $*"
  "$@"
}

# Reads a cdcr --json object on stdin and prints one field as a flat
# comma-separated list, the form the options take.
json_field() {
  python3 -c '
import json, sys
value = json.load(sys.stdin)[sys.argv[1]]
print(",".join(repr(x) for row in value for x in row))
' "$1"
}

heading "1. Forward kinematics of Table 1, case 2"
run "$cdcr" fk "${geometry[@]}" --cables "$table1_case2_cables_mm"
table1_pose=$("$cdcr" fk "${geometry[@]}" --cables "$table1_case2_cables_mm" --json | json_field pose)

heading "2. Inverse kinematics back to that pose"
echo "(8 joint variables for a 6-DOF pose: the joints may differ from step 1's)"
run "$cdcr" ik "${geometry[@]}" --pose "$table1_pose"
ik_cables_mm=$("$cdcr" ik "${geometry[@]}" --pose "$table1_pose" --json | json_field cables)

heading "3. Forward kinematics of the IK cable lengths"
run "$cdcr" fk "${geometry[@]}" --cables "$ik_cables_mm"
round_trip_pose=$("$cdcr" fk "${geometry[@]}" --cables "$ik_cables_mm" --json | json_field pose)

python3 - "$table1_pose" "$round_trip_pose" <<'PYTHON'
import sys

first, second = ([float(x) for x in arg.split(",")] for arg in sys.argv[1:3])
difference = max(abs(a - b) for a, b in zip(first, second))
tolerance = 1e-6
print(f"\nLargest difference between the poses of steps 1 and 3: {difference:.1e} (tolerance {tolerance:.0e})")
if difference > tolerance:
    sys.exit("demo: the round trip did not reproduce the pose")
PYTHON

out=build/demo
mkdir -p "$out"

heading "4. Simulated robot: 700 random workspace samples (the paper's protocol)"
run "$cdcr" simulate --samples 700 --seed 1 --out "$out/train.csv"

heading "5. Train: hyperparameters on 650 samples, validated on 50 held out; the exported float32 image fitted on all 700"
run "$cdcr" train --data "$out/train.csv" --out "$out/model.img"

heading "6. Check the image and export it for a board"
run "$cdcr" inspect "$out/model.img"
run "$cdcr" export --model "$out/model.img" --format hex --base-address 0x08040000 --out "$out/model.hex"
run "$cdcr" export --model "$out/model.img" --format c --out "$out/model_image.c"

heading "7. Accuracy on an independent test session of the same robot (200 samples)"
run "$cdcr" simulate --samples 200 --seed 1 --session 1 --out "$out/test.csv"
run "$cdcr" eval --model "$out/model.img" --data "$out/test.csv"

heading "8. The firmware runtime in closed loop with the simulated robot, 1 kHz for 3 s"
echo "(the same robot: targets it can reach, cable drives on the simulated bus)"
run build/bin/cdcr-runtime --image "$out/model.img" --sim --rate 1000 --seconds 3

heading "9. The same loop following a streamed circle: a pose target every cycle, 40 mm radius at 50 mm/s, recorded"
run build/bin/cdcr-runtime --image "$out/model.img" --sim --circle --circle-radius 40 --circle-speed 50 \
  --record "$out/circle.mcap"

heading "10. The recording, read back by the reference MCAP reader"
run node tools/view/clients/check_mcap.js "$out/circle.mcap" --runtime build/bin/cdcr-runtime --image "$out/model.img"
cat <<EOF

Open $out/circle.mcap in Foxglove or Lichtblick (Open local file; a 3D panel
shows /scene, plots /cables and /cables/following_error) or in PlotJuggler.
Live: build/bin/cdcr-runtime --image $out/model.img --sim --circle --view 8765,
then connect Foxglove to ws://127.0.0.1:8765 (tools/view/README.md).
EOF
