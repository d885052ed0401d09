#!/usr/bin/env bash
# Builds the project with AddressSanitizer and UndefinedBehaviorSanitizer (GCC) in BUILD (default
# build-sanitize/) and runs the whole default suite there. Exit 0: the suite passed and neither
# sanitizer reported anything (both abort on their first report). Usage:
# tests/tools/sanitized_suite.sh [BUILD]
# Warnings are not errors here: GCC 12 under -fsanitize=address gives false -Wmaybe-uninitialized in
# OpenMesh's headers; the default build (SHADOWBAKE_WERROR) checks warnings.
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
build=$(realpath -m "${1:-$here/build-sanitize}")
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSHADOWBAKE_SANITIZE=address,undefined -DSHADOWBAKE_WERROR=OFF >/dev/null
cmake --build "$build"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/tests/tools/lsan.supp:print_suppressions=0}
ctest --test-dir "$build" --output-on-failure -j2 -LE heavy
