#!/bin/sh
# socketcan.view_on_vcan: view_test.sh in User-Mode Linux, then its recording
# read by the reference MCAP reader on the host, every message checked
# against cdcr-runtime --replay (tools/view/clients/check_mcap.js).
#   view_on_vcan.sh <linux.uml> <runtime> <checker> <work dir> <cdcr> <node> <tools/view/clients>
set -eu
uml=$1 runtime=$2 checker=$3 work=$4 cli=$5 node=$6 clients=$7
"$(dirname "$0")/run_in_uml.sh" "$uml" "$runtime" "$checker" "$work" view_test.sh "$cli"
"$node" "$clients/check_mcap.js" "$work/view.mcap" --runtime "$runtime" --image "$work/model.img" \
  --require /scene,/tf,/tip/pose,/tip/nominal_pose,/tip/uncertainty,/cables,/status
