#!/usr/bin/env bash
# docs/figures/sgan_time.sh [REV] [REPEATS] — warm sGAN inference (Sgan::predict, one core) on
# fixtures/maps/sim-1.json, median of 300 queries, REPEATS times (default 3); with REV, the
# sgan.cpp of that revision is linked into a second copy of the harness and the two run
# alternately (one interleaved A/B run, as docs/heuristic.md reports). Needs build/release.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
rev=${1:-}
repeats=${2:-3}
b="$root/build/release/src/miner"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
flags=(-O3 -DNDEBUG -fopenmp -std=c++17 -I"$root/src" -isystem /usr/include/eigen3)
libs=("$b/heuristic/libminer_heuristic.a" "$b/plan/libminer_plan.a" "$b/world/libminer_world.a"
      "$b/core/libminer_core.a" -ldnnl -loctomap -loctomath -fopenmp)
c++ "${flags[@]}" "$root/docs/figures/sgan_time.cpp" -o "$work/new" "${libs[@]}"
if [ -n "$rev" ]; then
  # The old sgan.cpp with its own header (shadowing the current one); the rest of the library
  # is the current build's.
  mkdir -p "$work/inc/miner/heuristic"
  git -C "$root" show "$rev:src/miner/heuristic/sgan.cpp" > "$work/sgan_old.cpp"
  git -C "$root" show "$rev:src/miner/heuristic/sgan.hpp" > "$work/inc/miner/heuristic/sgan.hpp"
  c++ -I"$work/inc" "${flags[@]}" -c "$work/sgan_old.cpp" -o "$work/sgan_old.o"
  c++ -I"$work/inc" "${flags[@]}" "$root/docs/figures/sgan_time.cpp" "$work/sgan_old.o" -o "$work/old" "${libs[@]}"
fi
for _ in $(seq "$repeats"); do
  [ -n "$rev" ] && echo "$rev: $("$work/old" "$root/fixtures/maps/sim-1.json" 300)"
  echo "current: $("$work/new" "$root/fixtures/maps/sim-1.json" 300)"
done
