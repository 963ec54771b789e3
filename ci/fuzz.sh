#!/usr/bin/env bash
# ci/fuzz.sh — builds MINER's libFuzzer targets with clang (ASan + UBSan + libFuzzer) and runs
# each for SECONDS on a scratch copy of its seed corpus (fixtures/fuzz/<target>/), so the
# repository is never written. A crash, a sanitizer report, a timeout (> 10 s on one input) or
# an out-of-memory (> 2 GB) fails the run and leaves the input in build/fuzz/artifacts/.
#
#   bash ci/fuzz.sh [SECONDS]     # default 15 per target (the CI smoke run); hours for a campaign
#
# Targets (src/fuzz/): octree (MINER's .bt/.ot reader, REQ-WORLD-014), point_cloud (PLY/PCD,
# REQ-WORLD-018), map_json (map documents, REQ-WORLD-001/002). Needs clang and
# libclang-rt-14-dev (ci/setup.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-15}
out=build/fuzz
mkdir -p "$out/obj" "$out/artifacts"
flags=(-std=c++17 -O1 -g -fno-omit-frame-pointer -Isrc -isystem /usr/include/eigen3)
lib_san=(-fsanitize=fuzzer-no-link,address,undefined)
sources=(src/miner/core/*.cpp src/miner/world/*.cpp)
# Objects of the library code, rebuilt when their source is newer, two at a time.
printf '%s\n' "${sources[@]}" | xargs -P 2 -I{} bash -c '
  src={}; obj='"$out"'/obj/$(echo "$src" | tr / _).o
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ -n "$(find src/miner -name "*.hpp" -newer "$obj" -print -quit)" ]; then
    clang++ '"${flags[*]}"' '"${lib_san[*]}"' -c "$src" -o "$obj"
  fi'
status=0
for target in octree point_cloud map_json; do
  clang++ "${flags[@]}" -fsanitize=fuzzer,address,undefined "src/fuzz/fuzz_$target.cpp" "$out"/obj/*.o \
    -loctomap -loctomath -o "$out/fuzz_$target"
  corpus=$(mktemp -d)
  cp -r "fixtures/fuzz/$target/." "$corpus/"
  echo "ci/fuzz.sh: $target for ${seconds}s"
  if ! UBSAN_OPTIONS=halt_on_error=1 "$out/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -max_len=65536 -artifact_prefix="$out/artifacts/${target}-" -print_final_stats=1 "$corpus" 2>"$out/$target.log"; then
    tail -40 "$out/$target.log" >&2
    echo "ci/fuzz.sh: $target failed (input in $out/artifacts/)" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$out/$target.log" | tail -2
  fi
  rm -rf "$corpus"
done
exit "$status"
