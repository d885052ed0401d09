#!/usr/bin/env bash
# Bakes two scenes with --gltf and checks the .glb files: the Khronos glTF validator, then a
# three.js rendering in headless Chromium compared pixel by pixel with the bake's own lightmaps.
#
#   tests/web/run_gltf_checks.sh SHADOWBAKE_BINARY
#
# Needs node, Chromium at /usr/bin/chromium (or $CHROMIUM) and tests/web's packages:
#   npm ci --prefix tests/web
# Cases: (a) scenes/showcase, one lightmap per receiver; (b) scenes/room, packed into an atlas.
# Exits non-zero if a bake or a check fails; the bake folder is then kept for a look.
set -euo pipefail

if [[ $# -ne 1 ]]; then
  echo "usage: $0 SHADOWBAKE_BINARY" >&2
  exit 2
fi

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
binary="$1"
if [[ "$binary" != /* ]]; then binary="$PWD/$binary"; fi
if [[ ! -x "$binary" ]]; then
  echo "run_gltf_checks: $1 is not an executable shadowbake binary" >&2
  exit 2
fi
if ! command -v node >/dev/null 2>&1; then
  echo "run_gltf_checks: node is not installed (tests/web needs Node.js 18 or later)" >&2
  exit 2
fi
for package in three gltf-validator puppeteer-core pngjs; do
  if [[ ! -d "$here/node_modules/$package" ]]; then
    echo "run_gltf_checks: tests/web/node_modules is missing or incomplete; run: npm ci --prefix tests/web" >&2
    exit 2
  fi
done

work="$(mktemp -d "${TMPDIR:-/tmp}/shadowbake-gltf-checks.XXXXXX")"
keep=0
cleanup() {
  if [[ $keep -eq 0 ]]; then rm -rf "$work"; else echo "run_gltf_checks: the bakes are kept in $work" >&2; fi
}
trap cleanup EXIT

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f s", b - a }'; }

passed=0
failed=0
total_start="$(now)"
cd "$root"

# bake NAME SCENE ARGS...: bakes into $work/NAME; its output is shown only if it fails.
bake() {
  local name="$1" scene="$2"
  shift 2
  local start
  start="$(now)"
  if ! "$binary" bake "$scene" -o "$work/$name" "$@" -q >"$work/$name.log" 2>&1; then
    cat "$work/$name.log" >&2
    echo "run_gltf_checks: FAIL: the bake of $name failed: $binary bake $scene -o $work/$name $* -q" >&2
    keep=1
    exit 1
  fi
  echo "[$name] bake $scene $* ($(elapsed "$start"))"
}

# check NAME LABEL COMMAND...: runs one check, counts it.
check() {
  local name="$1" label="$2"
  shift 2
  local start
  start="$(now)"
  if "$@"; then
    passed=$((passed + 1))
    echo "[$name] $label: ok ($(elapsed "$start"))"
  else
    failed=$((failed + 1))
    keep=1
    echo "[$name] $label: FAILED ($(elapsed "$start"))"
  fi
}

bake showcase scenes/showcase/scene.toml --resolution 256 --samples 16 --encoding png --gltf
bake room-atlas scenes/room/scene.toml --texels-per-metre 40 --atlas 1024 --samples 16 --encoding png --gltf

for name in showcase room-atlas; do
  check "$name" "glTF validator" node "$here/validate_gltf.mjs" "$work/$name/scene.glb"
  check "$name" "three.js render check" node "$here/render_check.mjs" "$work/$name"
done

echo "run_gltf_checks: $(elapsed "$total_start") in all"
echo "web-checks: $passed passed, $failed failed"
[[ $failed -eq 0 ]]
