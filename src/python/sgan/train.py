#!/usr/bin/env python3
"""Trains the sGAN on a `miner dataset` folder and exports the weights for C++ inference.

    python3 src/python/sgan/train.py --data DIR --out DIR [options]

Objective (paper Sec. IV-A.2, "final objective"):
    theta* = alpha_1 L_sGAN + alpha_2 L_BCE(o, gt) + alpha_3 L_continuity(o) + alpha_4 L_safety(o, E)
with two discriminators D_connectivity(R | S), D_safety(R | E) trained on
    L_D = BCE(D(gt | c), 1) + BCE(D(o | c), 0)          (Eqs. connectivity_loss, safety_loss)
and the generator's adversarial term weighted as in Eq. (generator_loss):
    w_s = kappa L_Ds / (L_Dc + kappa L_Ds),  w_c = L_Dc / (L_Dc + kappa L_Ds)
    L_adv = w_s BCE(D_s(o | E), 1) + w_c BCE(D_c(o | S), 1)
(the non-saturating form of E[log D(G(N | E, S))]). Adam with beta = (0.5, 0.99).

Deterministic for a seed on a given machine and thread count: the shuffles, the noise and
the initial weights come from torch generators seeded from --seed, and deterministic
algorithms are enforced.

Writes OUT/sgan.bin (weights, miner-tensors-v1), OUT/reference.bin (inputs and outputs of
the first validation samples, for the C++ agreement test) and OUT/metrics.json.
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import torch
import torch.nn.functional as F

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import model as sgan  # noqa: E402
import quality  # noqa: E402
import tensors  # noqa: E402

# Defaults and why:
#   alpha1 0.05  the adversarial terms shape the region; BCE (alpha2 1) carries the signal early
#   alpha3 0.5   continuity: jumps over delta = 0.5 between neighbours (a region's edge is one jump)
#   alpha4 50    safety is a mean over all n^3 cells, so its per-cell gradient needs ~50x to
#                outweigh BCE's on the solid cells the network sees in E
#   pos_weight 5 the target is ~1.4 % of the grid; weighting it keeps the thresholded region
#                from breaking up (connectivity)
#   kappa 1      safety and connectivity discriminators equally important (Eq. generator_loss)
#   thresholds   candidates for the raw region's threshold, chosen on the validation split
DEFAULTS = dict(epochs=4, batch=8, lr_g=2e-3, lr_d=2e-4, kappa=1.0, alpha1=0.05, alpha2=1.0, alpha3=0.5,
                alpha4=50.0, delta=0.5, pos_weight=5.0, width=8, threshold=0.5, seed=1, threads=2,
                max_train=0, references=2, thresholds="0.5")


def load_split(data, split):
    path = os.path.join(data, "dataset.json")
    if not os.path.isfile(path):
        raise SystemExit(f"train: {path} not found (make one with `miner dataset`)")
    with open(path) as f:
        meta = json.load(f)
    if meta.get("format") != "miner-dataset-v1":
        raise SystemExit(f"train: {data}/dataset.json is not a miner-dataset-v1 folder")
    nx, ny, nz = meta["dims"]
    parts = []
    for shard in meta["splits"][split]["shards"]:
        path = os.path.join(data, shard["file"])
        raw = np.fromfile(path, dtype=np.uint8)
        if raw.size != shard["count"] * 3 * nx * ny * nz:
            raise SystemExit(f"train: {path} is truncated")
        parts.append(raw.reshape(shard["count"], 3, nz, ny, nx))
    if not parts:
        return meta, np.zeros((0, 3, nz, ny, nx), np.uint8)
    return meta, np.concatenate(parts)


def to_inputs(batch):
    """uint8 [B, 3, n, n, n] -> (E/2, S, T, solid) float tensors [B, 1, n, n, n]."""
    t = torch.from_numpy(batch.astype(np.float32))
    env, state, target = t[:, 0:1], t[:, 1:2], t[:, 2:3]
    return env * 0.5, state, target, (env == 2).float()


def bce(p, label):
    return F.binary_cross_entropy(p, torch.full_like(p, label))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", required=True, help="miner dataset folder")
    ap.add_argument("--out", required=True, help="output folder (created)")
    for k, v in DEFAULTS.items():
        ap.add_argument("--" + k.replace("_", "-"), type=type(v), default=v)
    ap.add_argument("--device", default="cpu", help="cpu or cuda")
    a = ap.parse_args(argv)
    if a.epochs < 1 or a.batch < 1 or a.width < 1 or a.threads < 1:
        raise SystemExit("train: --epochs, --batch, --width and --threads must be >= 1")
    try:
        candidates = sorted({float(t) for t in a.thresholds.split(",")} | {a.threshold})
    except ValueError:
        raise SystemExit("train: --thresholds must be numbers separated by commas")
    if not all(0.0 < t < 1.0 for t in candidates):
        raise SystemExit("train: --threshold and --thresholds must be in (0, 1)")

    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    torch.manual_seed(a.seed)
    dev = torch.device(a.device)
    meta, train = load_split(a.data, "train")
    _, val = load_split(a.data, "val")
    if a.max_train > 0:
        train = train[:a.max_train]
    if len(train) == 0 or len(val) == 0:
        raise SystemExit("train: the dataset needs train and val samples")
    if any(d % 8 for d in meta["dims"]):
        raise SystemExit("train: the grid dims must be divisible by 8")

    gen = torch.Generator().manual_seed(a.seed)
    G = sgan.Generator(a.width).to(dev)
    Dc, Ds = sgan.Discriminator().to(dev), sgan.Discriminator().to(dev)
    opt_g = torch.optim.Adam(G.parameters(), lr=a.lr_g, betas=(0.5, 0.99))
    opt_d = torch.optim.Adam(list(Dc.parameters()) + list(Ds.parameters()), lr=a.lr_d, betas=(0.5, 0.99))
    pos_weight = torch.tensor(a.pos_weight, device=dev)

    log, t0 = [], time.time()
    steps_per_epoch = (len(train) + a.batch - 1) // a.batch
    for epoch in range(a.epochs):
        order = torch.randperm(len(train), generator=gen).numpy()
        sums = np.zeros(6)
        for step in range(steps_per_epoch):
            idx = np.sort(order[step * a.batch:(step + 1) * a.batch])
            env, state, target, solid = (x.to(dev) for x in to_inputs(train[idx]))
            noise = torch.randn(env.shape, generator=gen).to(dev)
            o = G(env, state, noise)
            # Discriminators: real = ground truth, fake = generated (Eqs. connectivity/safety_loss).
            l_dc = bce(Dc(target, state), 1.0) + bce(Dc(o.detach(), state), 0.0)
            l_ds = bce(Ds(target, env), 1.0) + bce(Ds(o.detach(), env), 0.0)
            opt_d.zero_grad()
            (l_dc + l_ds).backward()
            opt_d.step()
            # Generator (Eq. generator_loss weights, then the final objective).
            ldc, lds = l_dc.detach(), l_ds.detach()
            w_s = a.kappa * lds / (ldc + a.kappa * lds)
            w_c = ldc / (ldc + a.kappa * lds)
            adv = w_s * bce(Ds(o, env), 1.0) + w_c * bce(Dc(o, state), 1.0)
            logits = torch.logit(o.clamp(1e-6, 1 - 1e-6))
            l_bce = F.binary_cross_entropy_with_logits(logits, target, pos_weight=pos_weight)
            l_cont = sgan.continuity_loss(o, a.delta)
            l_safe = sgan.safety_loss(o, solid)
            loss = a.alpha1 * adv + a.alpha2 * l_bce + a.alpha3 * l_cont + a.alpha4 * l_safe
            opt_g.zero_grad()
            loss.backward()
            opt_g.step()
            sums += [loss.item(), adv.item(), l_bce.item(), l_cont.item(), l_safe.item(), (l_dc + l_ds).item()]
        q = evaluate(G, val, a, dev)
        entry = {"epoch": epoch + 1,
                 **{k: float(v / steps_per_epoch) for k, v in
                    zip(["loss_g", "adversarial", "bce", "continuity", "safety", "loss_d"], sums)}, **q}
        log.append(entry)  # the files hold no wall-clock time: same seed, same bytes
        print(json.dumps({**entry, "seconds": round(time.time() - t0, 1)}), flush=True)

    # The raw region's threshold: the candidate with the best connectivity + safety on the
    # validation split (ties: the one nearest 0.5).
    if len(candidates) > 1:
        scores = []
        for t in candidates:
            q = evaluate(G, val, a, dev, t)
            scores.append((q["val_connectivity_rate_raw"] + q["val_safety_rate_raw"], -abs(t - 0.5), t, q))
        best = max(scores)
        a.threshold = best[2]
        log[-1]["threshold_scan"] = [{"threshold": t, **q} for _, _, t, q in scores]
        log[-1].update(best[3])
        print(json.dumps({"threshold": a.threshold, **best[3]}), flush=True)
    os.makedirs(a.out, exist_ok=True)
    args = list(argv if argv is not None else sys.argv[1:])
    # The recorded command leaves out where the files went, so the same training gives
    # the same bytes wherever it writes them.
    for i, x in enumerate(args):
        if x == "--out":
            del args[i:i + 2]
            break
        if x.startswith("--out="):
            del args[i]
            break
    export(G, a, meta, val, log, dev, args)


def evaluate(G, val, a, dev, threshold=None):
    """Raw connectivity and safety rates on the validation split (quality.py, REQ-HEUR-004)."""
    G.eval()
    conn = safe = 0
    gen = torch.Generator().manual_seed(a.seed + 1)
    with torch.no_grad():
        for i in range(0, len(val), a.batch):
            b = val[i:i + a.batch]
            env, state, _, _ = to_inputs(b)
            noise = torch.randn(env.shape, generator=gen)
            p = G(env.to(dev), state.to(dev), noise.to(dev)).cpu().numpy()[:, 0]
            for k in range(len(b)):
                region = p[k] >= (a.threshold if threshold is None else threshold)
                c, s = quality.connected_and_safe(region, b[k, 0], b[k, 1])
                conn += c
                safe += s
    G.train()
    return {"val_connectivity_rate_raw": conn / len(val), "val_safety_rate_raw": safe / len(val)}


def export(G, a, meta, val, log, dev, argv):
    G = G.cpu().eval()
    names = [name for name, _, _ in sgan.GENERATOR_LAYERS]
    weights = []
    for name in names:
        conv = G.convs[name]
        weights.append((name + ".weight", conv.weight.detach().numpy()))
        weights.append((name + ".bias", conv.bias.detach().numpy()))
    arch = {"name": "sgan-unet4", "width": a.width, "dims": meta["dims"], "layers": names,
            "environment_scale": 0.5, "threshold": a.threshold}
    training = {k: getattr(a, k) for k in DEFAULTS}
    training.update({"data": os.path.basename(os.path.normpath(a.data)), "data_seed": meta["seed"],
                     "data_preset": meta["preset"],
                     "train_samples": int(min(meta["splits"]["train"]["count"], a.max_train or 1 << 30)),
                     "command": "python3 src/python/sgan/train.py " + " ".join(argv) + " --out OUT"})
    tensors.write(os.path.join(a.out, "sgan.bin"), "sgan-weights", weights,
                  {"architecture": arch, "training": training, "final": log[-1]})
    # Reference tensors: the first validation samples with fixed noise, through PyTorch.
    refs = []
    gen = torch.Generator().manual_seed(a.seed + 2)
    with torch.no_grad():
        for k in range(min(a.references, len(val))):
            env, state, _, _ = to_inputs(val[k:k + 1])
            noise = torch.randn(env.shape, generator=gen)
            out = G(env, state, noise)
            refs += [(f"{k}.environment", env[0, 0].numpy()), (f"{k}.state", state[0, 0].numpy()),
                     (f"{k}.noise", noise[0, 0].numpy()), (f"{k}.output", out[0, 0].numpy())]
    tensors.write(os.path.join(a.out, "reference.bin"), "sgan-reference", refs,
                  {"samples": min(a.references, len(val)), "weights": "sgan.bin"})
    with open(os.path.join(a.out, "metrics.json"), "w") as f:
        json.dump({"format": "miner-sgan-training-v1", "architecture": arch, "training": training, "epochs": log},
                  f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()
