#!/usr/bin/env bash
# docs/figures/encode.sh MINER [REPEATS] — the heuristic query's cost on a map of 226 000 small
# boxes (issue 16 item 4: "a map of 226k boxes encodes in <= 20 ms") and on the sim fixture
# maps: median encode, inference and filter ms of `miner heuristic` over REPEATS runs (default 5).
# The box map is drawn from a fixed seed by Debian's python3 (no download).
set -euo pipefail
miner=${1:?usage: encode.sh MINER [REPEATS]}
repeats=${2:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 - "$work/boxes226k.json" <<'PY'
import json, random, sys
random.seed(1)
boxes = []
for _ in range(226000):
    x, y, z = random.uniform(0, 99), random.uniform(0, 99), random.uniform(0, 39)
    s = random.uniform(0.05, 0.6)
    boxes.append({"type": "box", "min": [round(x, 3), round(y, 3), round(z, 3)],
                  "max": [round(min(x + s, 100), 3), round(min(y + s, 100), 3), round(min(z + s, 40), 3)]})
json.dump({"format": "miner-map-v1", "bounds": {"min": [0, 0, 0], "max": [100, 100, 40]}, "resolution": 0.5,
           "obstacles": boxes, "query": {"start": [1, 1, 1], "goal": [98, 98, 2], "robot_radius": 0.0}},
          open(sys.argv[1], "w"))
PY
root=$(cd "$(dirname "$0")/../.." && pwd)
echo "| map | boxes | encode ms (median) | inference ms | filter ms | runs |"
echo "|---|---|---|---|---|---|"
for map in "$work/boxes226k.json" "$root/fixtures/maps/sim-1.json" "$root/fixtures/maps/sim-2.json" "$root/fixtures/maps/sim-3.json"; do
  for _ in $(seq "$repeats"); do "$miner" heuristic --map "$map" --out "$work/h.json" --json; done |
    /usr/bin/python3 -c "
import json, sys, statistics
docs, text = [], sys.stdin.read()
dec = json.JSONDecoder(); i = 0
while i < len(text):
    text_i = text[i:].lstrip()
    if not text_i: break
    d, n = dec.raw_decode(text_i); docs.append(d); i = len(text) - len(text_i) + n
m = json.load(open('$map'))
med = lambda k: statistics.median(d[k] for d in docs)
print(f\"| {'$map'.split('/')[-1]} | {len(m['obstacles'])} | {med('encode_ms'):.2f} | {med('inference_ms'):.2f} | {med('filter_ms'):.2f} | {len(docs)} |\")
"
done
