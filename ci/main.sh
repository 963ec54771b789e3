#!/usr/bin/env bash
# ci/main.sh — the README's first command: set up, build (Release) and run the main
# job: it generates a seeded 100 m cluttered map, plans on it with A* and with MINER-RRT*
# on the shipped sGAN's filtered region, then flies the default scenario in closed loop
# (`miner fly`). Results go to run/quickstart/.
set -euo pipefail
cd "$(dirname "$0")/.."

bash ci/setup.sh
cmake --workflow --preset release

out=run/quickstart
mkdir -p "$out"
set -x
build/release/miner map gen --preset sim --seed 7 --out "$out/map.json"
build/release/miner map info --map "$out/map.json"
build/release/miner astar --map "$out/map.json" --out "$out/astar.json"
build/release/miner plan --map "$out/map.json" --planner miner --target-factor 1.0 --out "$out/plan.json"
build/release/miner fly --out "$out/fly"
