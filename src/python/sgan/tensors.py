"""The `miner-tensors-v1` container, read by src/miner/heuristic/tensor_file.hpp:

    bytes 0-7   magic "MINERTS1"
    bytes 8-11  header length H (uint32, little endian)
    H bytes     header, UTF-8 JSON: {"format": "miner-tensors-v1", "kind": ..., "meta": {...},
                "tensors": [{"name", "shape", "offset", "count"}...],
                "data_bytes": D, "data_fnv1a64": "16 hex digits"}
    D bytes     float32 little endian; tensor t is count floats from byte offset (from here)

The checksum (FNV-1a, 64 bit, over the D data bytes) lets a reader refuse a truncated or
altered file before it runs anything.
"""
import json
import struct

import numpy as np

MAGIC = b"MINERTS1"


def fnv1a64(data: bytes) -> int:
    h = 0xCBF29CE484222325
    arr = np.frombuffer(data, dtype=np.uint8)
    # Vectorising FNV is not possible (each step depends on the last); chunked Python is
    # fast enough for the few MB the weights and references take.
    for b in arr.tobytes():
        h ^= b
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def write(path, kind, tensors, meta):
    """tensors: list of (name, numpy array); written in order as float32."""
    entries, chunks, offset = [], [], 0
    for name, arr in tensors:
        a = np.ascontiguousarray(np.asarray(arr, dtype="<f4"))
        entries.append({"name": name, "shape": list(a.shape), "offset": offset, "count": int(a.size)})
        chunks.append(a.tobytes())
        offset += a.nbytes
    data = b"".join(chunks)
    header = {"format": "miner-tensors-v1", "kind": kind, "meta": meta, "tensors": entries,
              "data_bytes": len(data), "data_fnv1a64": "%016x" % fnv1a64(data)}
    text = json.dumps(header, sort_keys=True).encode()
    with open(path, "wb") as f:
        f.write(MAGIC + struct.pack("<I", len(text)) + text + data)


def read(path):
    with open(path, "rb") as f:
        blob = f.read()
    if blob[:8] != MAGIC:
        raise ValueError(f"{path}: not a miner-tensors-v1 file")
    (n,) = struct.unpack("<I", blob[8:12])
    header = json.loads(blob[12:12 + n])
    data = blob[12 + n:]
    if len(data) != header["data_bytes"] or "%016x" % fnv1a64(data) != header["data_fnv1a64"]:
        raise ValueError(f"{path}: data truncated or altered")
    out = {}
    for t in header["tensors"]:
        out[t["name"]] = np.frombuffer(data, dtype="<f4", count=t["count"], offset=t["offset"]).reshape(t["shape"])
    return header, out
