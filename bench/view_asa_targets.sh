#!/usr/bin/env bash
# Issue 16's end-to-end targets, beside bench/view_asa_bench (pictures,
# display faces, per-update ASA, in-process orbit):
#  1. the client on loopback, ASA (view-dependent, the default camera) against
#     --no-asa and --view-independent, whole process (wall and CPU time);
#  2. the viewer's scripted orbit under Xvfb (MESHSTREAM_VIEWER_ORBIT): ASA ms
#     per re-run (the `view` events) and whether any frame lacked a mesh.
# The streams are the big synthetic models scale_bench --make-only writes.
#
# Usage: bench/view_asa_targets.sh BUILD_DIR BIG_DIR [MODEL...]
#   (default models: dragon_x1 dragon_x2; BIG_DIR holds MODEL.hcs)
# Prints one line per run; the raw JSON events stay in $OUT (default
# /tmp/view_asa_targets). ORBIT_ONLY=1 skips the client runs (1.).
set -euo pipefail
build=${1:?build dir}
big=${2:?folder with the .hcs streams}
shift 2
models=("$@")
[ ${#models[@]} -gt 0 ] || models=(dragon_x1 dragon_x2)
out=${OUT:-/tmp/view_asa_targets}
rm -rf "$out"
mkdir -p "$out/models" "$out/cache"
for m in "${models[@]}"; do ln -s "$big/$m.hcs" "$out/models/$m.hcs"; done

server_pid=
cleanup() { [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null || true; }
trap cleanup EXIT
"$build/server/meshstream-server" --models "$out/models" --cache "$out/cache" \
  --listen 127.0.0.1:0 >"$out/server.log" 2>&1 &
server_pid=$!
for _ in $(seq 100); do
  grep -q "^listening on " "$out/server.log" 2>/dev/null && break
  sleep 0.2
done
address=$(sed -n 's/^listening on \([^ ]*\).*/\1/p' "$out/server.log" | head -1)
[ -n "$address" ] || { cat "$out/server.log"; exit 1; }
client="$build/client/meshstream-client"

# One client run: wall s, CPU s (user + sys), peak RSS, updates, last display faces.
run_client() {
  local name=$1
  shift
  /usr/bin/time -f "%e %U %S %M" -o "$out/$name.time" "$client" "$address" "$@" --json --quiet \
    >"$out/$name.json" 2>"$out/$name.err" || { echo "$name failed: $(tail -2 "$out/$name.err")"; return; }
  python3 - "$out/$name" <<'EOF'
import json, sys, statistics
base = sys.argv[1]
wall, user, sys_, rss = open(base + ".time").read().split()[:4]
events = [json.loads(l) for l in open(base + ".json") if l.startswith("{")]
ref = [e for e in events if e.get("event") == "refinement"]
asa = [e.get("asa_ms", 0) for e in ref]
done = [e for e in events if e.get("event") == "done"]
print(f"{base.split('/')[-1]}: wall {float(wall):.2f} s, CPU {float(user) + float(sys_):.2f} s, "
      f"peak RSS {int(rss) // 1024} MB, {len(ref)} updates, "
      f"asa_ms median {statistics.median(asa) if asa else 0:.1f} max {max(asa) if asa else 0:.1f}, "
      f"last display_faces {ref[-1]['display_faces'] if ref else 0}, "
      f"done elapsed {done[-1]['elapsed_ms'] / 1000 if done else 0:.2f} s, "
      f"budget_limited {sum(1 for e in ref if e.get('budget_limited'))}")
EOF
}

echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for m in "${models[@]}"; do
  [ -z "${ORBIT_ONLY:-}" ] || break
  for round in 1 2; do
    run_client "$m.no-asa.$round" "$m" --no-asa
    run_client "$m.asa.$round" "$m" --asa on
    run_client "$m.vi.$round" "$m" --asa on --view-independent
  done
done
echo "load after client runs: $(cut -d' ' -f1-3 /proc/loadavg)"

# The viewer's scripted orbit: 2 degrees a frame, 1280 x 720, until frame
# ${ORBIT_FRAMES:-600}, ASA on the complete mesh too; ASA per re-run from
# the `view` events.
for m in "${models[@]}"; do
  name="$m.orbit"
  MESHSTREAM_VIEWER_ORBIT=2 /usr/bin/time -f "%e %U %S %M" -o "$out/$name.time" \
    xvfb-run -a -s "-screen 0 1280x720x24" "$client" "$address" "$m" --asa on --asa-complete --view --json \
    --width 1280 --height 720 --exit-after "${ORBIT_FRAMES:-600}" >"$out/$name.json" \
    2>"$out/$name.err" || { echo "$name failed: $(tail -2 "$out/$name.err")"; continue; }
  python3 - "$out/$name" <<'EOF'
import json, sys, statistics
base = sys.argv[1]
events = [json.loads(l) for l in open(base + ".json") if l.startswith("{")]
# Re-runs for the camera once the whole stream is decoded (--asa-complete
# keeps ASA on there): the target's "at 3.5M decoded triangles".
last_record = max((i for i, e in enumerate(events) if e.get("event") == "refinement"), default=-1)
after = [e for e in events[last_record + 1:] if e.get("event") == "view"]
# asa_path "none": the renderer's cull once the camera rested (no ASA ran).
views = [e for e in after if e.get("asa_path") != "none"]
rests = [e for e in after if e.get("asa_path") == "none"]
early = sum(1 for e in events[:last_record] if e.get("event") == "view" and e.get("asa_path") != "none")
culls = sorted(e.get("cull_ms", 0) for e in views + rests if e.get("cull_ms", 0) > 0)
ms = sorted(e.get("asa_ms", 0) for e in views)
region = [e.get("region_faces", 0) for e in views]
paths = {}
for e in views:
    paths[e.get("asa_path")] = paths.get(e.get("asa_path"), 0) + 1
viewer = [l.strip() for l in open(base + ".err") if l.startswith("viewer:")]
print(f"{base.split('/')[-1]}: {early} camera re-runs while streaming; on the complete mesh "
      f"{len(views)} re-runs, asa_ms median "
      f"{statistics.median(ms) if ms else 0:.1f}, p90 {ms[int(0.9 * (len(ms) - 1))] if ms else 0:.1f}, "
      f"max {ms[-1] if ms else 0:.1f}; region faces median {statistics.median(region) if region else 0:.0f}; "
      f"paths {paths}; {len(culls)} pipeline culls ({len(rests)} at rest), cull_ms median "
      f"{statistics.median(culls) if culls else 0:.1f}; {viewer[-1] if viewer else 'no viewer line'}")
EOF
done
echo "load after orbits: $(cut -d' ' -f1-3 /proc/loadavg)"
