#!/usr/bin/env bash
# docs/figures/query_time.sh [REV] [REPEATS] [MAP...] — warm region queries (heuristic::query_region:
# encode + inference + filter, one core) on the fixture maps (default fixtures/maps/sim-*.json),
# medians of REPEATS (default 200); with REV, the library of that revision is built in a
# scratch worktree and the two binaries run alternately, three rounds (one interleaved A/B run).
# Needs build/release (and, with REV, the release preset's packages).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
rev=${1:-}
repeats=${2:-200}
shift $(( $# > 2 ? 2 : $# )) || true
maps=("$@")
[ ${#maps[@]} -eq 0 ] && maps=("$root"/fixtures/maps/sim-*.json)
work=$(mktemp -d)
trap 'rm -rf "$work"; [ -n "$rev" ] && git -C "$root" worktree remove --force "$work/old-tree" 2>/dev/null || true' EXIT
link() {  # link SRC_ROOT BUILD OUT
  local b="$2/src/miner"
  c++ -O3 -DNDEBUG -fopenmp -std=c++17 -I"$1/src" -isystem /usr/include/eigen3 "$root/docs/figures/query_time.cpp" \
    -o "$3" "$b/heuristic/libminer_heuristic.a" "$b/plan/libminer_plan.a" "$b/world/libminer_world.a" \
    "$b/core/libminer_core.a" -ldnnl -loctomap -loctomath -fopenmp
}
link "$root" "$root/build/release" "$work/new"
if [ -n "$rev" ]; then
  git -C "$root" worktree add --detach "$work/old-tree" "$rev" > /dev/null 2>&1
  cmake -S "$work/old-tree" -B "$work/old-build" -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build "$work/old-build" --target miner_heuristic miner_plan miner_world miner_core -j2 > /dev/null
  link "$work/old-tree" "$work/old-build" "$work/old"
fi
for _ in 1 2 3; do
  [ -n "$rev" ] && { echo "$rev:"; "$work/old" "$repeats" "${maps[@]}"; }
  echo "current:"; "$work/new" "$repeats" "${maps[@]}"
done
