#!/usr/bin/env bash
# CTest's runner of tests/blender/addon_test.py (label `blender`): Blender headless with the
# factory settings and its user folders inside the scratch folder, so that installing the add-on
# touches nothing of the user's. Exit 77 (skipped) where Blender is not on PATH.
#   run_addon_test.sh SHADOWBAKE WORKDIR [--picture PNG]
set -euo pipefail
shadowbake=$1
work=$2
shift 2
if ! command -v blender >/dev/null 2>&1; then
  echo "addon_test: SKIP: no blender on PATH (Debian: apt-get install blender python3-numpy)"
  exit 77
fi
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
export BLENDER_USER_SCRIPTS="$work/user/scripts" BLENDER_USER_CONFIG="$work/user/config"
exec blender -b --factory-startup --python-exit-code 1 --python "$here/addon_test.py" -- \
  --shadowbake "$shadowbake" --work "$work/run" "$@"
