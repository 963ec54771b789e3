#!/usr/bin/env python3
"""Sets the raw region's threshold stored with trained weights, recording why.

    python3 src/python/sgan/set_threshold.py --weights IN.bin --threshold T [--rule fixed|widest] --reason TEXT --out OUT.bin

train.py picks the threshold on the validation split by the grid rates (REQ-HEUR-004), the
only ones Python can compute; the strict rates (REQ-HEUR-011) need the continuous maps, which
`miner bench heuristic --split val` measures. When those pick another threshold, this writes
the same tensors (same bytes, same checksum) with architecture.threshold = T and
final.threshold_override = {from, to, reason} in the header. --rule sets
architecture.threshold_rule (REQ-HEUR-016): "widest" lowers the threshold per query to the
widest start-goal chain's bottleneck when that is smaller (the file's rule is kept when absent).
"""
import argparse
import json
import struct
import sys


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--weights", required=True)
    ap.add_argument("--threshold", required=True, type=float)
    ap.add_argument("--rule", choices=("fixed", "widest"), default=None)
    ap.add_argument("--reason", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    if not 0.0 < a.threshold < 1.0:
        raise SystemExit("set_threshold: --threshold must be in (0, 1)")
    blob = open(a.weights, "rb").read()
    if blob[:8] != b"MINERTS1" or len(blob) < 12:
        raise SystemExit(f"set_threshold: {a.weights} is not a miner-tensors-v1 file")
    n = struct.unpack("<I", blob[8:12])[0]
    header = json.loads(blob[12:12 + n])
    if header.get("kind") != "sgan-weights":
        raise SystemExit(f"set_threshold: {a.weights} holds {header.get('kind')}, not sgan-weights")
    arch = header["meta"]["architecture"]
    override = {"from": arch["threshold"], "to": a.threshold, "reason": a.reason}
    if a.rule is not None:
        override["rule"] = {"from": arch.get("threshold_rule", "fixed"), "to": a.rule}
        arch["threshold_rule"] = a.rule
    header["meta"]["final"]["threshold_override"] = override
    arch["threshold"] = a.threshold
    text = json.dumps(header, sort_keys=True).encode()
    with open(a.out, "wb") as f:
        f.write(blob[:8] + struct.pack("<I", len(text)) + text + blob[12 + n:])


if __name__ == "__main__":
    sys.exit(main())
