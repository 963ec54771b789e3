#!/usr/bin/env bash
# cites: REQ-HARNESS-006
# ci/fuzz.sh — builds MINER's libFuzzer targets with clang (ASan + UBSan + libFuzzer) and runs
# each on a scratch copy of its seed corpus (fixtures/fuzz/<target>/), so the repository is
# never written. A crash, a sanitizer report, an exception other than miner::Error, a timeout
# (> 10 s on one input) or an out-of-memory (> 2 GB) fails the run and leaves the input in
# build/fuzz/artifacts/; every finding becomes a regression test (the input under
# fixtures/fuzz/<target>/ and a unit test of the fault).
#
#   bash ci/fuzz.sh [SECONDS [RUNS]]   # per target: stop after SECONDS or RUNS executions,
#                                      # whichever comes first (ci/test.sh: 8 s or 20000
#                                      # runs, the smoke; ctest -L fuzz: 1e6 runs each)
#
# The mutation stream is seeded (MINER_FUZZ_SEED, default 20261122), so CI explores the same
# inputs every time (up to libFuzzer's corpus reduction, which is not bit-for-bit stable);
# MINER_FUZZ_SEED=0 lets libFuzzer draw a fresh seed (exploration campaigns); MINER_FUZZ_TARGETS
# ("dataset cli") runs a subset.
#
# Targets (src/fuzz/fuzz_<target>.cpp): octree (.bt/.ot, REQ-WORLD-014), point_cloud (PLY/PCD,
# REQ-WORLD-018), map_json (REQ-WORLD-001/002), scenario (REQ-FLIGHT-007), vehicle
# (REQ-FLIGHT-001), problem (REQ-TRAJ-006/007), region (REQ-PLAN-005), tensors (sGAN weights
# and reference files, REQ-HEUR-006), campaign (bench merge shards, REQ-REPORT-006), dataset
# (dataset --merge parts and the split reader, REQ-HEUR-001/REQ-REPORT-006), cli (the argument
# layer of every command, REQ-CLI-001..003). Needs Debian's clang-16, libclang-rt-16-dev,
# libfuzzer-16-dev and libomp-16-dev (ci/setup.sh installs them; MINER_FUZZ_CXX picks another). Prints each
# target's executions and corpus coverage, and writes them to build/fuzz/summary.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-6}
runs=${2:--1}
seed=${MINER_FUZZ_SEED:-20261122}
targets=(octree point_cloud map_json scenario vehicle problem region tensors campaign dataset cli)
if [ -n "${MINER_FUZZ_TARGETS:-}" ]; then read -r -a targets <<<"$MINER_FUZZ_TARGETS"; fi  # a subset
cxx=${MINER_FUZZ_CXX:-clang++-16}
out=build/fuzz
mkdir -p "$out/obj" "$out/artifacts"
ompl_include=$(ls -d /usr/include/ompl-* | head -1)
flags=(-std=c++17 -O1 -g -fno-omit-frame-pointer -Isrc -isystem /usr/include/eigen3 -isystem "$ompl_include"
       -DEIGEN_MALLOC_ALREADY_ALIGNED=1 -DMINER_WITH_OMPL=1 -DGFLAGS_IS_A_DLL=0 -DGLOG_CUSTOM_PREFIX_SUPPORT)
lib_san=(-fsanitize=fuzzer-no-link,address,undefined)
# The library code the parsers live in (the linker takes from the archive only what a target uses).
sources=(src/miner/core/*.cpp src/miner/world/*.cpp src/miner/traj/*.cpp src/miner/plan/*.cpp
         src/miner/flight/*.cpp src/miner/pipeline/*.cpp src/miner/heuristic/*.cpp src/miner/report/*.cpp src/bench/*.cpp
         src/cli/cli.cpp src/cli/*_commands.cpp)
# Objects, rebuilt when their source or any header is newer, two at a time; all of them when the
# compiler or the flags change.
stamp="$("$cxx" --version | head -1) ${flags[*]} ${lib_san[*]}"
if [ "$(cat "$out/obj/stamp" 2>/dev/null)" != "$stamp" ]; then
  rm -f "$out"/obj/*.o
  echo "$stamp" >"$out/obj/stamp"
fi
printf '%s\n' "${sources[@]}" | xargs -P 2 -I{} bash -c '
  src={}; obj='"$out"'/obj/$(echo "$src" | tr / _).o
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ] || [ -n "$(find src/miner src/bench src/cli -name "*.hpp" -newer "$obj" -print -quit)" ]; then
    '"$cxx"' '"${flags[*]}"' '"${lib_san[*]}"' -c "$src" -o "$obj.tmp" && mv "$obj.tmp" "$obj"
  fi'
# The sources CMake generates (the shipped sGAN weights, the report's scripts, the default
# scenario) from a configure-only run of the project, so they are the product's own.
cmake -S . -B "$out/gen" -DMINER_TESTS=OFF >"$out/gen.log"
mapfile -t generated < <(find "$out/gen/src" -name "*.cpp" | sort)
for src in "${generated[@]}"; do
  obj="$out/obj/gen_$(basename "$src" .cpp).o"
  if [ ! -f "$obj" ] || [ "$src" -nt "$obj" ]; then "$cxx" -std=c++17 -O0 -Isrc -isystem /usr/include/eigen3 -c "$src" -o "$obj"; fi
done
rm -f "$out/libminer_fuzz.a"
objects=()
for src in "${sources[@]}"; do objects+=("$out/obj/$(echo "$src" | tr / _).o"); done
for src in "${generated[@]}"; do objects+=("$out/obj/gen_$(basename "$src" .cpp).o"); done
ar rcs "$out/libminer_fuzz.a" "${objects[@]}"
libs=(-loctomap -loctomath -lompl -lboost_serialization -lboost_filesystem -lboost_system
      /usr/lib/x86_64-linux-gnu/libceres.a -lglog -lgflags -lspqr -lcholmod -lamd -lcamd -lccolamd -lcolamd
      -lsuitesparseconfig -lcxsparse -llapack -lblas -lsundials_cvode -lsundials_nvecserial -ldnnl -lgomp
      -lpthread -ldl)
status=0
: >"$out/summary.txt"
for target in "${targets[@]}"; do
  "$cxx" "${flags[@]}" -fsanitize=fuzzer,address,undefined "src/fuzz/fuzz_$target.cpp" "$out/libminer_fuzz.a" \
    "${libs[@]}" -o "$out/fuzz_$target"
  corpus=$(mktemp -d)
  cp -r "fixtures/fuzz/$target/." "$corpus/"
  echo "ci/fuzz.sh: $target for ${seconds}s or $runs runs, seed $seed"
  if ! UBSAN_OPTIONS=halt_on_error=1 "$out/fuzz_$target" -max_total_time="$seconds" -runs="$runs" -seed="$seed" -timeout=10 \
      -rss_limit_mb=2048 -max_len=65536 -artifact_prefix="$out/artifacts/${target}-" -print_final_stats=1 \
      "$corpus" 2>"$out/$target.log"; then
    tail -40 "$out/$target.log" >&2
    echo "ci/fuzz.sh: $target failed (input in $out/artifacts/)" >&2
    status=1
  else
    execs=$(grep -oE "stat::number_of_executed_units: *[0-9]+" "$out/$target.log" | grep -oE "[0-9]+$" || true)
    cover=$(grep -E "^#[0-9]+[[:space:]]+DONE" "$out/$target.log" | grep -oE "cov: [0-9]+ ft: [0-9]+ corp: [0-9/]+[a-zA-Z]*" | head -1 || true)
    line="$target: ${execs:-?} executions, ${cover:-no final stats}"
    echo "$line" | tee -a "$out/summary.txt"
  fi
  rm -rf "$corpus"
done
exit "$status"
