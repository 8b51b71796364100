#!/usr/bin/env bash
# Regenerates the README's snapshot strip: a local meshstream-server streams
# the Stanford bunny (../shared/meshes/bun_zipper.ply) to meshstream-client,
# which renders the display mesh off-screen (OSMesa, no display needed) after
# an early, a middle and the last record, with ASA and without (--no-asa).
# Then the live window (under xvfb-run, so no display is needed) while a
# throttled server streams the same model, captured with its panel.
#   docs/images/make_snapshot_strip.sh [BUILD_DIR]   (default: build/)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
meshes="${MESHSTREAM_TEST_MESHES:-$root/../shared/meshes}"
out="$root/docs/images"
server_bin="$build/server/meshstream-server"
client_bin="$build/client/meshstream-client"
for f in "$server_bin" "$client_bin" "$meshes/bun_zipper.ply"; do
  [ -e "$f" ] || { echo "make_snapshot_strip: missing $f" >&2; exit 1; }
done

work="$(mktemp -d)"
mkdir "$work/models"
cp "$meshes/bun_zipper.ply" "$work/models/bunny.ply"
servers=()
trap 'for p in "${servers[@]}"; do kill $p 2>/dev/null; wait $p 2>/dev/null; done; rm -rf "$work"' EXIT
start_server() {  # NAME [server options...]: sets $address
  local name="$1"
  shift
  "$server_bin" --models "$work/models" --cache "$work/cache" --listen 127.0.0.1:0 "$@" \
    > "$work/$name.out" 2> "$work/$name.log" &
  servers+=($!)
  address=""
  for _ in $(seq 1 300); do
    address="$(sed -n 's/^listening on //p' "$work/$name.out")"
    [ -n "$address" ] && return 0
    sleep 0.1
  done
  echo "make_snapshot_strip: server did not start" >&2
  cat "$work/$name.log" >&2
  exit 1
}
start_server fast

snap() {  # NAME RECORD|final [client options...]: prints the record's facts
  local name="$1" record="$2"
  shift 2
  local at=()
  [ "$record" != final ] && at=(--snapshot-at "$record")
  "$client_bin" "$address" bunny --json --width 320 --height 240 --snapshot "$out/$name.png" \
      "${at[@]}" "$@" |
    grep '"event":"refinement"' |
    { if [ "$record" = final ]; then tail -1; else grep "\"index\":$record,"; fi; } |
    sed -E 's/.*"bytes":([0-9]+).*"display_faces":([0-9]+).*"faces":([0-9]+).*"index":([0-9]+).*/'"$name"': record \4, \1 bytes, \3 decoded faces, \2 display faces/'
}
snap bunny-early-asa 0
snap bunny-early-no-asa 0 --no-asa
# The middle picture: about 6 % of the stream (record 14 of the current
# encoder's 256); MIDDLE_RECORD picks another.
middle="${MIDDLE_RECORD:-14}"
snap bunny-middle-asa "$middle"
snap bunny-middle-no-asa "$middle" --no-asa
snap bunny-final-asa final
snap bunny-final-no-asa final --no-asa
echo "wrote $out/bunny-{early,middle,final}-{asa,no-asa}.png"

# The window mid-stream at 10 KB/s, colouring what ASA did (orange: faces
# ASA split, green: bisected to close the mesh), closed after 40 frames.
start_server slow --rate 10000
MESHSTREAM_VIEWER_CAPTURE="$out/viewer-window.png" MESHSTREAM_VIEWER_COLORING=kinds \
  xvfb-run -a -s "-screen 0 1280x800x24" \
  "$client_bin" "$address" bunny --quiet --view --exit-after 40 --width 960 --height 600
echo "wrote $out/viewer-window.png"
