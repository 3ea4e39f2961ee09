#!/usr/bin/env bash
# Regenerates tools/view/demo_view.png, the README's picture of the view: the
# demo's robot (build/demo/model.img, from `bash tools/demo.sh`) following its
# streamed circle, drawn by the project's page (tools/view/web) in headless
# Chromium (tools/view/clients/screenshot.js).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

image=build/demo/model.img
runtime=build/bin/cdcr-runtime
out=tools/view/demo_view.png

die() {
  echo "make_readme_screenshot: $*" >&2
  exit 1
}
[[ -f $image ]] || die "no $image: run bash tools/demo.sh first"
[[ -x $runtime ]] || die "no $runtime: build it (cmake --build build --target cdcr-runtime)"
[[ -d tools/view/clients/node_modules/three ]] || die "no npm packages: run npm ci in tools/view/clients"

log=$(mktemp)
"$runtime" --image "$image" --sim --circle --view 0 >/dev/null 2>"$log" &
pid=$!
trap 'kill "$pid" 2>/dev/null || true; rm -f "$log"' EXIT

port=
for _ in $(seq 100); do
  port=$(sed -n 's|^view: ws://127.0.0.1:\([0-9]*\).*|\1|p' "$log")
  [[ -n $port ]] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.1
done
[[ -n $port ]] || die "cdcr-runtime served no view: $(tail -n 1 "$log")"

# About 3 s into the 6 s circle: a wait, not a count of scenes drawn, as
# headless Chromium draws fewer than the view's 30 a second (~10 on a loaded
# two-core host). Portrait, for the tall robot.
sleep 1.5
scene_time=$(node tools/view/clients/screenshot.js --ws "ws://127.0.0.1:$port" --out "$out" \
  --width 720 --height 800 --cx -0.05 --cz 0.255 --ppm 1300)
echo "wrote $out (scene at $scene_time)"
