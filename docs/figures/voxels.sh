#!/usr/bin/env bash
# Prints docs/maps.md's voxel-map cost table (REQ-WORLD-017): two simulated scans at 5 cm of
# the size of a real indoor scan (13 x 14 x 5.9 m, ~8.7M voxels): an office floor (rooms) and a
# cluttered room, each flown by a 360 x 90 deg lidar (miner map scan), then `miner bench voxels`
# (100 000 random queries of each kind, robot radius 0.2 m, median of 5 loads), and the scan
# fixtures. Quiet machine for the timings.
#   bash docs/figures/voxels.sh [build/release/miner]
set -euo pipefail
miner=${1:-build/release/miner}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$miner" map gen --preset rooms --seed 7 --size 13 14 5.9 --resolution 0.05 --out "$dir/rooms.json" >/dev/null
"$miner" map scan --map "$dir/rooms.json" --range 8 --rays 360 64 --fov 360 90 --spacing 0.5 --resolution 0.05 \
  --radius 0.3 --body-radius 0.5 --out "$dir/rooms-5cm.bt" >/dev/null
"$miner" map gen --preset cluttered --seed 7 --size 13 14 5.9 --resolution 0.05 --obstacles 110 --out "$dir/clut.json" >/dev/null
"$miner" map scan --map "$dir/clut.json" --range 8 --rays 360 64 --fov 360 90 --spacing 0.5 --resolution 0.05 \
  --radius 0.2 --body-radius 0.3 --out "$dir/cluttered-5cm.bt" >/dev/null
echo "| map | voxels | occupied | unknown | .bt bytes | load ms | memory MB | point q/s | segment q/s | ray q/s | A* grid ms | channel E ms |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for m in "$dir/rooms-5cm.bt" "$dir/cluttered-5cm.bt" fixtures/scans/indoor-1-lidar.bt fixtures/scans/rooms-depth.bt fixtures/scans/forest-lidar.bt; do
  "$miner" bench voxels --map "$m" --json | python3 -c "
import json, os, sys
d = json.load(sys.stdin); v = d['voxels']
print('| %s | %d x %d x %d | %d | %d | %d | %.0f | %.1f | %.0f | %.0f | %.0f | %.0f | %.1f |' % (
  os.path.basename(d['map']), *v['dims'], v['occupied'], v['unknown'], os.path.getsize(d['map']), d['load_ms'],
  (v['layer_bytes'] + v['field_bytes']) / 1e6, d['point']['per_second'], d['segment']['per_second'],
  d['ray']['per_second'], d['astar_grid_ms'], d['encode_ms']))"
done
