#!/usr/bin/env bash
# CTest's runner of tests/blender/modal_test.py (label `blender`): Blender with a window, on a
# virtual X server (Xvfb, Mesa's software OpenGL), its user folders inside the test's folder.
# Exit 77 (skipped) where Blender or xvfb-run is not on PATH.
#   run_modal_test.sh SHADOWBAKE WORKDIR
set -euo pipefail
shadowbake=$1
work=$2
for tool in blender xvfb-run; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "modal_test: SKIP: no $tool on PATH (Debian: apt-get install blender python3-numpy xvfb xauth)"
    exit 77
  fi
done
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
export BLENDER_USER_SCRIPTS="$work/user/scripts" BLENDER_USER_CONFIG="$work/user/config"
exec xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup --enable-event-simulate \
  --python "$here/modal_test.py" -- --shadowbake "$shadowbake" --work "$work/run"
