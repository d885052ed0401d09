#!/bin/bash
# OpenArena's maps as the game shipped them (../shared/assets/openarena/: 224 and 1,916 lights,
# each with its q3map2 range), as a check under the CTest labels `heavy;levels` (docs/testing.md;
# figures in docs/performance.md, "Levels with many lights"). Per map, the default bake:
#   - against the reference at 64 samples with the same reach, RMSE at most 0.01 (measured
#     0.002-0.003, most of it the reference's own noise; the corpus bench's --levels run measures
#     both against the reference at 1,024);
#   - peak resident memory under 512 MiB (/usr/bin/time's %M);
#   - the manifest says how many lights reach a texel at most, and no library message (OpenMesh's
#     "add_face") reaches the terminal;
#   - oacmpdm5 with each light's own image and the shadow masks (--per-light --shadowmask): peak
#     under 512 MiB (224 full-size images took 1,391 MiB; they are kept by the tiles each light
#     reaches) and a file per light.
# Usage: openarena_levels_test.sh SHADOWBAKE ASSETS_DIR WORK_DIR. Exits 77 (skipped) where the
# levels are missing.
set -euo pipefail
shadowbake=$1 assets=$2 work=$3
if [[ ! -f $assets/openarena/oacmpdm5.toml ]]; then
  echo "skipped: $assets/openarena is missing (set SHADOWBAKE_SHARED_ASSETS)"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
status=0

for map in oacmpdm5 oacmpctf3; do
  scene=$assets/openarena/$map.toml
  /usr/bin/time -f %M -o "$work/$map.peak" "$shadowbake" bake "$scene" -o "$work/$map" \
    --no-cache 2> "$work/$map.stderr"
  "$shadowbake" bake "$scene" -o "$work/$map.ref" --no-cache -q --method reference --samples 64
  peak_kib=$(tail -1 "$work/$map.peak")
  echo "$map: peak $((peak_kib / 1024)) MiB"
  if ((peak_kib >= 512 * 1024)); then
    echo "FAIL: $map peaks at $((peak_kib / 1024)) MiB, not under 512"
    status=1
  fi
  if grep -q "add_face\|PolyMeshT" "$work/$map.stderr"; then
    echo "FAIL: $map: a library's message reached the terminal:"
    grep "add_face\|PolyMeshT" "$work/$map.stderr" | head -3
    status=1
  fi
  if ! python3 -c "import json,sys; m=json.load(open(sys.argv[1])); \
sys.exit(0 if all(r.get('most_lights_per_texel', 0) > 0 for r in m['receivers']) else 1)" \
    "$work/$map/manifest.json"; then
    echo "FAIL: $map: the manifest does not say how many lights reach a texel"
    status=1
  fi
  if ! "$shadowbake" compare "$work/$map/world.exr" "$work/$map.ref/world.exr" \
    --fail-above rmse=0.01; then
    echo "FAIL: $map: the default is farther than 0.01 (RMSE) from the reference at 64"
    status=1
  fi
done

map=oacmpdm5
/usr/bin/time -f %M -o "$work/$map.per_light.peak" "$shadowbake" bake "$assets/openarena/$map.toml" \
  -o "$work/$map.per_light" --no-cache -q --per-light --shadowmask
peak_kib=$(tail -1 "$work/$map.per_light.peak")
echo "$map --per-light --shadowmask: peak $((peak_kib / 1024)) MiB"
if ((peak_kib >= 512 * 1024)); then
  echo "FAIL: $map with per-light images peaks at $((peak_kib / 1024)) MiB, not under 512"
  status=1
fi
lights=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['lights']))" \
  "$work/$map.per_light/manifest.json")
files=$(find "$work/$map.per_light" -name 'world.*.exr' | wc -l)
if ((files != lights)); then
  echo "FAIL: $map: $files per-light images for $lights lights"
  status=1
fi
exit $status
