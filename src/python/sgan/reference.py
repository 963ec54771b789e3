#!/usr/bin/env python3
"""Writes the reference tensors (reference.bin) of trained weights again, from the weights and
the validation data they were trained with, exactly as train.py's export writes them.

    python3 src/python/sgan/reference.py --weights W/sgan.bin --data fam-sim fam-indoor ... --out W/reference.bin

train.py writes reference.bin beside sgan.bin: the first validation samples (one per family in
turn, `references` of them) with noise from seed + 2, through PyTorch on the CPU. `miner sgan
check` compares MINER's C++ forward pass with it. Weights trained on a lent machine come back
without it (it is several MB); this rebuilds it on any machine from the same data folders, in
the order the weights' training record lists them (checked).
"""
import argparse
import os
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import model as sgan  # noqa: E402
import tensors  # noqa: E402
import train  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--weights", required=True)
    ap.add_argument("--data", required=True, nargs="+", help="the training's dataset folders, in its order")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    header, weights = tensors.read(a.weights)
    meta = header["meta"]
    arch, training = meta["architecture"], meta["training"]
    names = [os.path.basename(os.path.normpath(d)) for d in a.data]
    if names != training["data"]:
        raise SystemExit(f"reference: --data names {names}, the weights were trained on {training['data']}")
    G = sgan.Generator(arch["width"], arch.get("scale_channels", 0), arch.get("passability_channels", 0))
    G.load_state_dict({"convs." + k: torch.from_numpy(np.array(v)) for k, v in weights.items()}, strict=True)
    G.eval()
    _, val, val_sigma, val_family = train.load_families(a.data, "val", training.get("pool", 1))
    n = training["references"]
    gen = torch.Generator().manual_seed(training["seed"] + 2)
    picks = train.balanced_first(val_family, n)[:n] if len(val) else []
    refs = []
    with torch.no_grad():
        for k, v in enumerate(picks):
            env, state, _, _, passability = train.to_inputs(val[v:v + 1])
            noise = torch.randn(env.shape, generator=gen)
            sigma = torch.from_numpy(val_sigma[v:v + 1])
            out = G(env, state, noise, sigma, passability)
            refs += [(f"{k}.environment", env[0, 0].numpy()), (f"{k}.state", state[0, 0].numpy()),
                     (f"{k}.noise", noise[0, 0].numpy()), (f"{k}.output", out[0, 0].numpy())]
            if arch.get("passability_channels", 0):
                refs.append((f"{k}.passability", passability[0].numpy()))
            if arch.get("scale_channels", 0):
                refs.append((f"{k}.scale", sigma[0].numpy()))
    tensors.write(a.out, "sgan-reference", refs, {"samples": len(picks), "weights": os.path.basename(a.weights)})


if __name__ == "__main__":
    sys.exit(main())
