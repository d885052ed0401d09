#!/usr/bin/env bash
# Builds the libFuzzer target tests/fuzz/scene_fuzz.cpp with clang (fuzzer, AddressSanitizer,
# UndefinedBehaviorSanitizer) in BUILD (default build-fuzz/) and runs it for SECONDS (default 60)
# on a corpus seeded from scenes/ and tests/bad_inputs/. Exit 0: nothing found. Findings are kept
# as BUILD/crash-* files. Usage: tests/fuzz/run_fuzz.sh [SECONDS] [BUILD]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
seconds=${1:-60}
build=$(realpath -m "${2:-$here/build-fuzz}")
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DSHADOWBAKE_FUZZ=ON \
  -DSHADOWBAKE_TESTS=OFF >/dev/null
cmake --build "$build" --target shadowbake_fuzz_scene
corpus="$build/corpus"
mkdir -p "$corpus"
# Seeds: every scene file with each of its meshes (format byte, scene, NUL, mesh).
python3 - "$here" "$corpus" <<'PY'
import hashlib, pathlib, sys
root, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
extensions = ["obj", "ply", "gltf", "glb", "stl", "fbx", "off", "dae"]
for scene in list(root.glob("scenes/*/scene.toml")) + list(root.glob("tests/bad_inputs/*/scene.toml")):
    text = scene.read_bytes()
    for mesh in scene.parent.iterdir():
        ext = mesh.suffix[1:].lower()
        if ext not in extensions or not mesh.is_file() or mesh.stat().st_size > 400_000:
            continue
        renamed = text.replace(mesh.name.encode(), b"mesh." + ext.encode())
        seed = bytes([extensions.index(ext)]) + renamed + b"\0" + mesh.read_bytes()
        (out / hashlib.sha1(seed).hexdigest()).write_bytes(seed)
PY
cd "$build"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1:max_allocation_size_mb=2048}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/tests/tools/lsan.supp:print_suppressions=0}
./shadowbake_fuzz_scene -max_total_time="$seconds" -rss_limit_mb=4096 -malloc_limit_mb=2048 \
  -timeout=20 -print_final_stats=1 "$corpus"
