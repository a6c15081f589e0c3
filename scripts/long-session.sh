#!/usr/bin/env bash
# A long scripted viewer session (issue 41): orbit the camera, switch technique A through a
# cycle of techniques and parameter settings, turn the light at every switch (every technique
# and the reference are made again for each light), and print the resident memory every 10 s.
# Usage: scripts/long-session.sh [SECONDS (600)] [OUT (out/long-session.txt)]
# Needs a release build (make build) and xvfb-run when there is no display.
set -euo pipefail
secs=${1:-600}
out=${2:-out/long-session.txt}
mkdir -p "$(dirname "$out")"
bin=${SHADOWLAB:-target/release/shadowlab}
run=()
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
  run=(xvfb-run -a -s "-screen 0 1600x900x24")
fi
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
"${run[@]}" "$bin" view --scene courtyard -t sm --size 480x270 --exit-after-s "$secs" --orbit 0.5 \
  --cycle sm --cycle sm:pcf=3 --cycle vsm --cycle evsm --cycle msm --cycle csm --cycle sdsm \
  --cycle lt --cycle virtual --cycle iasm --cycle rtw --cycle notw --cycle mdsm --cycle esm:res=1024 \
  --cycle-every 40 --light-turn 7 --memory-every 10 --out "$(dirname "$out")" | tee "$out"
