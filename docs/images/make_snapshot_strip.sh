#!/usr/bin/env bash
# Regenerates the README's snapshot strip: a local meshstream-server streams
# the Stanford bunny (../shared/meshes/bun_zipper.ply) to meshstream-client,
# which renders the display mesh off-screen (OSMesa, no display needed) after
# an early, a middle and the last record, with ASA and without (--no-asa).
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
"$server_bin" --models "$work/models" --cache "$work/cache" --listen 127.0.0.1:0 \
  > "$work/server.out" 2> "$work/server.log" &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null; rm -rf "$work"' EXIT
address=""
for _ in $(seq 1 300); do
  address="$(sed -n 's/^listening on //p' "$work/server.out")"
  [ -n "$address" ] && break
  sleep 0.1
done
[ -n "$address" ] || { echo "make_snapshot_strip: server did not start" >&2; cat "$work/server.log" >&2; exit 1; }

snap() {  # NAME [client options...]
  local name="$1"
  shift
  "$client_bin" "$address" bunny --quiet --width 320 --height 240 --snapshot "$out/$name.png" "$@"
}
snap bunny-early-asa --snapshot-at 0
snap bunny-early-no-asa --snapshot-at 0 --no-asa
snap bunny-middle-asa --snapshot-at 3
snap bunny-middle-no-asa --snapshot-at 3 --no-asa
snap bunny-final-asa
snap bunny-final-no-asa --no-asa
echo "wrote $out/bunny-{early,middle,final}-{asa,no-asa}.png"
