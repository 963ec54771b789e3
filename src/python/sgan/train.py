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
import hashlib
import json
import math
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

# Defaults and why (the shipped fixtures/sgan weights were trained with them; docs/heuristic.md
# has the sweep that chose them):
#   alpha1 0.002 the adversarial terms: the discriminators soon tell the generated region from the
#                A* tube (loss_D -> 0.005); with a larger weight (0.05, 0.01, 0.005 tried) their
#                gradient dragged BCE back up every epoch and the raw region stayed 55-75 % connected
#   alpha2 1     BCE against the target carries the signal
#   alpha3 0.5   continuity: jumps over delta = 0.5 between neighbours (a region's edge is one jump)
#   alpha4 100   safety is a mean over all n^3 cells, so its per-cell gradient needs ~100x to
#                outweigh BCE's on the solid cells the network sees in E
#   pos_weight 8 the target is ~1.4 % of the grid; weighting it keeps the thresholded region
#                from breaking up (connectivity). alpha1, alpha4 and pos_weight changed together
#                in the sweep (docs/heuristic.md); their separate effects were not measured
#   kappa 1      safety and connectivity discriminators equally important (Eq. generator_loss)
#   batch 32     keeps a GPU busy (an epoch of 21 600 samples: 14 s on one H100)
#   thresholds   candidates for the raw region's threshold, chosen on the validation split
#   augment 1    each sample is drawn through a random symmetry of the map's horizontal square
#                (x and y mirrors, and the x <-> y swap when the grid and the bounds are square):
#                it maps a query and its A* path to a query of the same map family and a path of
#                the same length, so it is 8x data for free; gravity (z) is never flipped
#   augment 2    every symmetry of the cube (3 mirrors x 6 axis orders: 48) when the grid is a
#                cube (nx = ny = nz, always for `miner dataset`): sigma is permuted with the axes,
#                so the network is told the metric size of what became each axis. The query is
#                geometric (A* and RRT* see no gravity), so a turned map with its turned path is
#                still a map and its optimal path: walls with doors become floors with holes,
#                a forest's trunks become beams, the cross-family variety a held-out family needs
#   schedule     "cosine": both learning rates decay as (1 + cos(pi t)) / 2 over the run, t the
#                share of steps done, so the last epochs settle instead of oscillating
#   select       "best": export the epoch (and threshold) with the best validation
#                connectivity + safety (GAN training oscillates); "last": the last epoch
#   val_samples  validation samples scored after each epoch (0: all of them), the first of
#                each family in turn
#   pool         1: train on the dataset's grid; 2: on a grid of half the cells per axis, made from
#                the dataset's (E: free when all 8 cells are, solid when all 8 are, else partial,
#                which is what `miner dataset --dims` gives for the coarse cell; S: the state cubes
#                drawn again on the coarse grid from the index's start, goal and bounds, as C++'s
#                encode_state does; T: a coarse cell is in T when one of its cells is): the
#                network is 8x cheaper to run (docs/heuristic.md)
#   scale_channels  3: the network is told sigma, its cells' metric size (model.py); 0: the
#                graph of the weights trained before (one map family, one scale)
#   passability_channels  3: the network also reads P, per cell whether its free space joins
#                its two faces across x, y, z (dataset v2, grid.hpp): a wall thinner than a cell
#                and the door through it are both "partial" in E, so without P no network can tell
#                the one cell of a wall that lets a path through (held-out rooms: 1 of 20 maps
#                strictly connected, docs/heuristic.md); 0: the graph without it
DEFAULTS = dict(epochs=10, batch=32, lr_g=2e-3, lr_d=2e-4, kappa=1.0, alpha1=0.002, alpha2=1.0, alpha3=0.5,
                alpha4=100.0, delta=0.5, pos_weight=8.0, width=8, scale_channels=3, passability_channels=3,
                threshold=0.5, seed=1, threads=2,
                max_train=0, references=2, thresholds="0.3,0.4,0.5,0.6,0.7,0.8", augment=1, schedule="cosine",
                select="best", val_samples=400, pool=1)


def cell_of(lo, hi, dims, p):
    """C++'s heuristic::cell_of: the cell holding p, clamped onto the grid (x, y, z)."""
    return [int(min(max(math.floor((p[a] - lo[a]) / ((hi[a] - lo[a]) / dims[a])), 0), dims[a] - 1)) for a in range(3)]


def pool_samples(x, index, meta, pool):
    """uint8 [N, C, nz, ny, nx] on the dataset's grid (C = 4: E, S, T, P) -> uint8 [N, 3, ...] (E, S,
    T; P is dropped) on the grid of dims / pool (see `pool` above); meta["dims"] is updated."""
    n, ch, nz, ny, nx = x.shape
    if nx % pool or ny % pool or nz % pool:
        raise SystemExit(f"train: --pool {pool} does not divide the grid {meta['dims']}")
    d = [nx // pool, ny // pool, nz // pool]
    blocks = x.reshape(n, ch, d[2], pool, d[1], pool, d[0], pool)  # P (channel 3) is dropped
    lo_e, hi_e = blocks[:, 0].min(axis=(2, 4, 6)), blocks[:, 0].max(axis=(2, 4, 6))
    env = np.where(hi_e == 0, 0, np.where(lo_e == 2, 2, 1)).astype(np.uint8)
    target = blocks[:, 2].max(axis=(2, 4, 6))
    state = np.zeros_like(target)
    r = int(meta.get("dilation", 1))
    for k, e in enumerate(index):
        lo, hi = e["bounds"]["min"], e["bounds"]["max"]
        for p in (e["start"], e["goal"]):
            c = cell_of(lo, hi, d, p)
            state[k, max(0, c[2] - r):c[2] + r + 1, max(0, c[1] - r):c[1] + r + 1, max(0, c[0] - r):c[0] + r + 1] = 1
    meta["dims"] = d
    return np.ascontiguousarray(np.stack([env, state, target], axis=1))


def load_split(data, split, pool=1):
    """One folder's split: (meta, uint8 [N, 4, nz, ny, nx] (E, S, T, P), float32 sigma [N, 3]), on the
    dataset's grid or, with pool > 1, on the coarser one of pool_samples."""
    path = os.path.join(data, "dataset.json")
    if not os.path.isfile(path):
        raise SystemExit(f"train: {path} not found (make one with `miner dataset`)")
    with open(path) as f:
        meta = json.load(f)
    if meta.get("format") != "miner-dataset-v3":
        raise SystemExit(f"train: {data}/dataset.json is not a miner-dataset-v3 folder "
                         "(v2 had no hash of its index files: generate it again)")
    nx, ny, nz = meta["dims"]
    ch = len(meta["channels"])  # E, S, T, P
    parts = []
    for shard in meta["splits"][split]["shards"]:
        path = os.path.join(data, shard["file"])
        raw = np.fromfile(path, dtype=np.uint8)
        if raw.size != shard["count"] * ch * nx * ny * nz:
            raise SystemExit(f"train: {path} is truncated")
        if hashlib.sha256(raw.tobytes()).hexdigest() != shard["sha256"]:
            raise SystemExit(f"train: {path}: its SHA-256 differs from the one dataset.json records")
        parts.append(raw.reshape(shard["count"], ch, nz, ny, nx))
    x = np.concatenate(parts) if parts else np.zeros((0, ch, nz, ny, nx), np.uint8)
    index_path = os.path.join(data, meta["splits"][split]["index"])
    with open(index_path, "rb") as f:
        index_bytes = f.read()
    # The index is hashed in dataset.json like the shards (REQ-HEUR-001): an edited one is refused.
    if hashlib.sha256(index_bytes).hexdigest() != meta["splits"][split].get("index_sha256"):
        raise SystemExit(f"train: {index_path}: its SHA-256 differs from the one dataset.json records")
    index = json.loads(index_bytes)
    if len(index) != len(x) or any("bounds" not in e for e in index):
        raise SystemExit(f"train: {index_path} must hold one entry with the map's bounds per sample "
                         "(a dataset written before the bounds were recorded: generate it again)")
    if pool > 1:
        x = pool_samples(x, index, meta, pool)
    sigma = np.array([sgan.scale_input(e["bounds"]["min"], e["bounds"]["max"], meta["dims"], meta["robot_radius"])
                      for e in index], dtype=np.float64).astype(np.float32).reshape(-1, 3)
    return meta, x, sigma


def load_families(folders, split, pool=1):
    """The folders' split joined: (metas, uint8 samples, float32 sigma, int family of each sample)."""
    metas, xs, sigmas, family = [], [], [], []
    for i, d in enumerate(folders):
        meta, x, sigma = load_split(d, split, pool)
        if metas and meta["dims"] != metas[0]["dims"]:
            raise SystemExit(f"train: {d} has a {meta['dims']} grid, {folders[0]} a {metas[0]['dims']} one")
        metas.append(meta)
        xs.append(x)
        sigmas.append(sigma)
        family.append(np.full(len(x), i, dtype=np.int64))
    return metas, np.concatenate(xs), np.concatenate(sigmas), np.concatenate(family)


def balanced_first(family, n):
    """Indices of about n samples, the first of each family in turn (all when n is 0 or more
    than there are), so a validation subset scores every family."""
    if n == 0 or n >= len(family):
        return np.arange(len(family))
    groups = [np.flatnonzero(family == f) for f in np.unique(family)]
    per = -(-n // len(groups))
    return np.sort(np.concatenate([g[:per] for g in groups]))


def to_inputs(batch):
    """uint8 [B, C, n, n, n] (numpy or torch; C = 3: E, S, T, or 4 with P) -> (E/2, S, T, solid)
    float tensors [B, 1, n, n, n] and the blocked bits 1 - P_a for a = x, y, z as 0/1 [B, 3, n, n, n]
    (None when C = 3): 0 on free cells, so the input stays sparse like E and S, and max-pooled to
    the coarse conditions it means "some cell here is blocked across a" (a wall's orientation)."""
    u = torch.from_numpy(batch) if isinstance(batch, np.ndarray) else batch
    t = u[:, 0:3].float()
    env, state, target = t[:, 0:1], t[:, 1:2], t[:, 2:3]
    passability = None
    if u.shape[1] > 3:
        p = u[:, 3:4]
        passability = torch.cat([1.0 - ((p >> a) & 1).float() for a in range(3)], 1)
    return env * 0.5, state, target, (env == 2).float(), passability


def permute_bits(p, axes):
    """P bits (uint8) of a grid whose new axis a is old axis axes[a]: new bit a = old bit axes[a]."""
    out = torch.zeros_like(p)
    for a in range(3):
        out |= ((p >> axes[a]) & 1) << a
    return out


def square_grid(meta):
    """True when the x <-> y swap maps the grid onto itself (nx = ny); sigma's x and y are
    swapped with it, so a 60 x 40 m floor becomes a 40 x 60 m one the network is told of."""
    nx, ny, _ = meta["dims"]
    return nx == ny


def cube_grid(meta):
    """True when every axis order maps the grid onto itself (nx = ny = nz)."""
    nx, ny, nz = meta["dims"]
    return nx == ny == nz


# The six orders of the axes (x, y, z) = (0, 1, 2): new axis a is old axis AXIS_ORDERS[p][a].
AXIS_ORDERS = [(0, 1, 2), (1, 0, 2), (0, 2, 1), (2, 1, 0), (1, 2, 0), (2, 0, 1)]


def augment(batch, sigma, code, swap_xy, cube=False):
    """Applies per sample the symmetry code to uint8 [B, C, nz, ny, nx] (P's bits, channel 3, turned
    with the axes) and its sigma [B, 3]
    (code: an int tensor [B] on the batch's device). Bit 0: mirror x, bit 1: mirror y; without
    cube, bit 2: swap x and y (when swap_xy); with cube, bit 2: mirror z and code >> 3 in 0..5
    picks the axis order AXIS_ORDERS[code >> 3], sigma permuted with it."""
    def where(mask, changed):
        return torch.where(mask.view(-1, 1, 1, 1, 1), changed, batch)

    def bit(b):
        return ((code >> b) & 1).bool()
    batch = where(bit(0), batch.flip(4))
    batch = where(bit(1), batch.flip(3))
    if cube:
        batch = where(bit(2), batch.flip(2))
        order = code >> 3
        # tensor dims (z, y, x) = (2, 3, 4): axis a (x = 0) lives in dim 4 - a
        out, out_sigma = batch, sigma
        for p, axes in enumerate(AXIS_ORDERS[1:], start=1):
            dims = [0, 1] + [4 - axes[2 - d] for d in range(3)]
            mask = order == p
            turned = batch.permute(*dims)
            if turned.shape[1] > 3:  # P's bits follow the axes
                turned = torch.cat([turned[:, :3], permute_bits(turned[:, 3:], axes)], 1)
            out = torch.where(mask.view(-1, 1, 1, 1, 1), turned, out)
            out_sigma = torch.where(mask.view(-1, 1), sigma[:, list(axes)], out_sigma)
        return out, out_sigma
    if swap_xy:
        swapped = batch.transpose(3, 4)
        if swapped.shape[1] > 3:  # P's x and y bits swap with the axes
            swapped = torch.cat([swapped[:, :3], permute_bits(swapped[:, 3:], (1, 0, 2))], 1)
        batch = where(bit(2), swapped)
        sigma = torch.where(bit(2).view(-1, 1), sigma[:, [1, 0, 2]], sigma)
    return batch, sigma


class ProgressBar:
    """The C++ ProgressBar's look (src/miner/core/progress.hpp) on stderr, drawn only when
    stderr is a terminal; redrawn when the bar or the percentage changes."""
    WIDTH = 30

    def __init__(self, label, total):
        self.label, self.total, self.drawn = label, max(total, 1), None
        self.out = sys.stderr if sys.stderr.isatty() else None

    def update(self, done):
        if self.out is None:
            return
        done = min(done, self.total)
        filled = self.WIDTH * done // self.total
        key = (filled, 100 * done // self.total)
        if key == self.drawn and done != self.total:
            return
        self.drawn = key
        self.out.write(f"\r{self.label} [{'#' * filled}{' ' * (self.WIDTH - filled)}] {done}/{self.total}")
        if done == self.total:
            self.out.write("\n")
        self.out.flush()


def bce(p, label):
    return F.binary_cross_entropy(p, torch.full_like(p, label))


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", required=True, nargs="+",
                    help="miner dataset folders (one per map family; the same grid dims)")
    ap.add_argument("--out", required=True, help="output folder (created)")
    for k, v in DEFAULTS.items():
        ap.add_argument("--" + k.replace("_", "-"), type=type(v), default=v)
    ap.add_argument("--device", default="cpu", help="cpu or cuda (same options, same bytes on one device kind)")
    ap.add_argument("--checkpoint", default="", help="write the whole training state here after every epoch")
    ap.add_argument("--resume", default="", help="continue from a --checkpoint file (same options)")
    ap.add_argument("--stop-after", type=int, default=0,
                    help="stop after this many epochs in all, leaving the --checkpoint to resume from (no export)")
    a = ap.parse_args(argv)
    if a.scale_channels not in (0, 3):
        raise SystemExit("train: --scale-channels must be 0 or 3")
    if a.epochs < 1 or a.batch < 1 or a.width < 1 or a.threads < 1:
        raise SystemExit("train: --epochs, --batch, --width and --threads must be >= 1")
    if a.schedule not in ("constant", "cosine"):
        raise SystemExit("train: --schedule must be constant or cosine")
    if a.select not in ("best", "last"):
        raise SystemExit("train: --select must be best or last")
    if a.augment not in (0, 1, 2) or a.val_samples < 0:
        raise SystemExit("train: --augment must be 0, 1 or 2 and --val-samples >= 0")
    if a.pool not in (1, 2):
        raise SystemExit("train: --pool must be 1 or 2")
    if a.passability_channels not in (0, 3):
        raise SystemExit("train: --passability-channels must be 0 or 3")
    if a.passability_channels and a.pool != 1:
        raise SystemExit("train: --pool 2 drops P (a coarse cell's passability is not its children's): "
                         "use --passability-channels 0")
    try:
        a.candidates = sorted({float(t) for t in a.thresholds.split(",")} | {a.threshold})
    except ValueError:
        raise SystemExit("train: --thresholds must be numbers separated by commas")
    if not all(0.0 < t < 1.0 for t in a.candidates):
        raise SystemExit("train: --threshold and --thresholds must be in (0, 1)")
    if a.device.startswith("cuda"):
        index = int(a.device.partition(":")[2] or 0) if a.device.partition(":")[2].isdigit() or a.device == "cuda" else -1
        if index < 0:
            raise SystemExit("train: --device must be cpu or cuda[:N]")
        if index >= torch.cuda.device_count():
            raise SystemExit(f"train: --device {a.device} asked for, but PyTorch sees "
                             f"{torch.cuda.device_count()} CUDA device(s)")
        # cuBLAS is deterministic only with a fixed workspace (PyTorch's reproducibility notes).
        os.environ.setdefault("CUBLAS_WORKSPACE_CONFIG", ":4096:8")
    elif a.device != "cpu":
        raise SystemExit("train: --device must be cpu or cuda[:N]")
    if a.stop_after and not a.checkpoint:
        raise SystemExit("train: --stop-after needs --checkpoint (else the work is lost)")
    return a


def main(argv=None):
    a = parse_args(argv)
    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    torch.backends.cudnn.benchmark = False
    torch.manual_seed(a.seed)
    dev = torch.device(a.device)
    metas, train, train_sigma, _ = load_families(a.data, "train", a.pool)
    _, val, val_sigma, val_family = load_families(a.data, "val", a.pool)
    meta = metas[0]
    if a.max_train > 0:
        train, train_sigma = train[:a.max_train], train_sigma[:a.max_train]
    if len(train) == 0 or len(val) == 0:
        raise SystemExit("train: the dataset needs train and val samples")
    if any(d % 8 for d in meta["dims"]):
        raise SystemExit("train: the grid dims must be divisible by 8")
    train = torch.from_numpy(train).to(dev)  # uint8 on the device: 96 KiB a sample
    train_sigma = torch.from_numpy(train_sigma).to(dev)
    swap_xy = square_grid(meta)
    cube = a.augment == 2
    if cube and not cube_grid(meta):
        raise SystemExit("train: --augment 2 needs a cubic grid (nx = ny = nz)")
    val_endpoints = [quality.endpoints(val[k, 1]) for k in range(len(val))]
    val_set = {"x": val, "sigma": val_sigma, "family": val_family, "ends": val_endpoints,
               "names": [m["preset"] for m in metas]}

    gen = torch.Generator().manual_seed(a.seed)  # shuffles and symmetries (CPU)
    noise_gen = torch.Generator(device=dev).manual_seed(a.seed + 3)  # noise, drawn on the device
    G = sgan.Generator(a.width, a.scale_channels, a.passability_channels).to(dev)
    Dc, Ds = sgan.Discriminator().to(dev), sgan.Discriminator().to(dev)
    opt_g = torch.optim.Adam(G.parameters(), lr=a.lr_g, betas=(0.5, 0.99))
    opt_d = torch.optim.Adam(list(Dc.parameters()) + list(Ds.parameters()), lr=a.lr_d, betas=(0.5, 0.99))
    pos_weight = torch.tensor(a.pos_weight, device=dev)
    log, best, first_epoch = [], None, 0
    if a.resume:
        state = torch.load(a.resume, map_location=dev, weights_only=False)  # our own file: RNG states, numpy scalars
        if state.get("options") != options_key(a):
            raise SystemExit(f"train: {a.resume} was written with other options; resume with the same ones")
        for m, k in ((G, "G"), (Dc, "Dc"), (Ds, "Ds"), (opt_g, "opt_g"), (opt_d, "opt_d")):
            m.load_state_dict(state[k])
        gen.set_state(state["gen"])
        noise_gen.set_state(state["noise_gen"].to(noise_gen.get_state().device))
        log, best, first_epoch = state["log"], state["best"], state["epoch"]

    t0 = time.time()
    steps_per_epoch = (len(train) + a.batch - 1) // a.batch
    total_steps = steps_per_epoch * a.epochs
    if first_epoch > a.epochs:
        raise SystemExit(f"train: {a.resume} has {first_epoch} epochs done, more than --epochs {a.epochs}")
    for epoch in range(first_epoch, a.epochs):
        order = torch.randperm(len(train), generator=gen)
        codes = torch.randint(0, 48 if cube else 8, (len(train),), generator=gen)
        sums = torch.zeros(6, dtype=torch.float64, device=dev)
        bar = ProgressBar(f"epoch {epoch + 1}/{a.epochs}", steps_per_epoch)
        for step in range(steps_per_epoch):
            bar.update(step)
            if a.schedule == "cosine":
                scale = 0.5 * (1.0 + math.cos(math.pi * (epoch * steps_per_epoch + step) / total_steps))
                for opt, lr in ((opt_g, a.lr_g), (opt_d, a.lr_d)):
                    for group in opt.param_groups:
                        group["lr"] = lr * scale
            idx = torch.sort(order[step * a.batch:(step + 1) * a.batch]).values
            batch, sigma = train[idx.to(dev)], train_sigma[idx.to(dev)]
            if a.augment:
                batch, sigma = augment(batch, sigma, codes[idx].to(dev), swap_xy, cube)
            env, state, target, solid, passability = to_inputs(batch)
            noise = torch.randn(env.shape, generator=noise_gen, device=dev)
            o = G(env, state, noise, sigma, passability)
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
            sums += torch.stack([loss, adv, l_bce, l_cont, l_safe, l_dc + l_ds]).detach().double()
        bar.update(steps_per_epoch)
        scan = evaluate(G, val_set, a, dev)
        pick = best_threshold(scan)
        entry = {"epoch": epoch + 1,
                 **{k: float(v / steps_per_epoch) for k, v in
                    zip(["loss_g", "adversarial", "bce", "continuity", "safety", "loss_d"], sums.tolist())},
                 "threshold": pick["threshold"], **quality_of(pick)}
        log.append(entry)  # the files hold no wall-clock time: same seed, same bytes
        score = pick["val_connectivity_rate_raw"] + pick["val_safety_rate_raw"]
        if best is None or a.select == "last" or score > best["score"]:
            best = {"score": score, "epoch": epoch + 1, "threshold": pick["threshold"],
                    "G": {k: v.detach().cpu().clone() for k, v in G.state_dict().items()}}
        print(json.dumps({**entry, "seconds": round(time.time() - t0, 1)}), flush=True)
        if a.checkpoint:
            save_checkpoint(a, epoch + 1, G, Dc, Ds, opt_g, opt_d, gen, noise_gen, log, best)
        if a.stop_after and epoch + 1 >= a.stop_after and epoch + 1 < a.epochs:
            print(f"train: stopped after epoch {epoch + 1}; resume with --resume {a.checkpoint}", flush=True)
            return

    # The exported generator: the best (or last) epoch, at the threshold that scored best on
    # the validation split (connectivity + safety; ties: the threshold nearest 0.5), scored
    # again on the whole validation split.
    G.load_state_dict(best["G"])
    a.threshold = best["threshold"]
    final = evaluate(G, val_set, a, dev, all_samples=True)
    summary = {"selected_epoch": best["epoch"], "threshold": a.threshold,
               **quality_of(next(q for q in final if q["threshold"] == a.threshold)),
               "by_family": next(q for q in final if q["threshold"] == a.threshold)["by_family"],
               "threshold_scan": [{k: v for k, v in q.items() if k != "by_family"} for q in final]}
    print(json.dumps({k: v for k, v in summary.items() if k != "threshold_scan"}), flush=True)
    os.makedirs(a.out, exist_ok=True)
    args = list(argv if argv is not None else sys.argv[1:])
    # The recorded command leaves out where the files went (and checkpoint paths), so the same
    # training gives the same bytes wherever it writes them.
    for flag in ("--out", "--checkpoint", "--resume", "--stop-after"):
        for i, x in enumerate(args):
            if x == flag:
                del args[i:i + 2]
                break
            if x.startswith(flag + "="):
                del args[i]
                break
    export(G, a, metas, val_set, log, summary, args)


def options_key(a):
    """The options a checkpoint must share with the run that resumes it. --epochs may differ:
    resuming with the epochs already done exports the best epoch so far; with more, the run
    goes on (the cosine schedule then follows the new total from the step reached)."""
    return json.dumps({k: getattr(a, k) for k in sorted(DEFAULTS) if k != "epochs"} | {"device": a.device},
                      sort_keys=True)


def save_checkpoint(a, epoch, G, Dc, Ds, opt_g, opt_d, gen, noise_gen, log, best):
    state = {"options": options_key(a), "epoch": epoch, "log": log, "best": best,
             "G": G.state_dict(), "Dc": Dc.state_dict(), "Ds": Ds.state_dict(),
             "opt_g": opt_g.state_dict(), "opt_d": opt_d.state_dict(),
             "gen": gen.get_state(), "noise_gen": noise_gen.get_state()}
    tmp = a.checkpoint + ".tmp"
    torch.save(state, tmp)
    os.replace(tmp, a.checkpoint)  # a checkpoint is never half-written


def quality_of(q):
    return {"val_connectivity_rate_raw": q["val_connectivity_rate_raw"], "val_safety_rate_raw": q["val_safety_rate_raw"]}


def best_threshold(scan):
    """The scan entry with the best connectivity + safety; ties go to the threshold nearest 0.5."""
    return max(scan, key=lambda q: (q["val_connectivity_rate_raw"] + q["val_safety_rate_raw"], -abs(q["threshold"] - 0.5)))


def evaluate(G, val_set, a, dev, all_samples=False):
    """Raw connectivity and safety rates on the validation split (quality.py, REQ-HEUR-004) at
    every candidate threshold, over all and per family; the first --val-samples samples
    (balanced over the families) unless all_samples."""
    G.eval()
    pick = balanced_first(val_set["family"], 0 if all_samples else a.val_samples)
    names = val_set["names"]
    conn = np.zeros((len(a.candidates), len(names)))
    safe = np.zeros((len(a.candidates), len(names)))
    count = np.bincount(val_set["family"][pick], minlength=len(names))
    gen = torch.Generator().manual_seed(a.seed + 1)
    with torch.no_grad():
        for i in range(0, len(pick), a.batch):
            ids = pick[i:i + a.batch]
            b = val_set["x"][ids]
            env, state, _, _, passability = to_inputs(b)
            noise = torch.randn(env.shape, generator=gen)
            sigma = torch.from_numpy(val_set["sigma"][ids])
            passability = passability.to(dev) if passability is not None else None
            p = G(env.to(dev), state.to(dev), noise.to(dev), sigma.to(dev), passability).cpu().numpy()[:, 0]
            for k, v in enumerate(ids):
                ends = val_set["ends"][v]
                fam = val_set["family"][v]
                solid = b[k, 0] == 2
                for j, t in enumerate(a.candidates):
                    region = p[k] >= t
                    conn[j, fam] += ends[0] is not None and quality.connected(region, *ends)
                    safe[j, fam] += not bool((region & solid).any())
    G.train()
    n = len(pick)
    return [{"threshold": t, "val_connectivity_rate_raw": conn[j].sum() / n, "val_safety_rate_raw": safe[j].sum() / n,
             "by_family": {names[f]: {"samples": int(count[f]),
                                      "val_connectivity_rate_raw": conn[j, f] / max(count[f], 1),
                                      "val_safety_rate_raw": safe[j, f] / max(count[f], 1)}
                           for f in range(len(names))}}
            for j, t in enumerate(a.candidates)]


def export(G, a, metas, val_set, log, summary, argv):
    G = G.cpu().eval()
    names = [name for name, _, _ in sgan.GENERATOR_LAYERS]
    weights = []
    for name in names:
        conv = G.convs[name]
        weights.append((name + ".weight", conv.weight.detach().numpy()))
        weights.append((name + ".bias", conv.bias.detach().numpy()))
    arch = {"name": "sgan-unet4", "width": a.width, "dims": metas[0]["dims"], "layers": names,
            "environment_scale": 0.5, "threshold": a.threshold, "scale_channels": a.scale_channels}
    if a.passability_channels:
        arch["passability_channels"] = a.passability_channels
    if a.scale_channels:
        arch["scale_divisor"] = sgan.SCALE_DIVISOR
    training = {k: getattr(a, k) for k in DEFAULTS}
    training.update({"data": [os.path.basename(os.path.normpath(d)) for d in a.data],
                     "data_seed": [m["seed"] for m in metas], "data_preset": [m["preset"] for m in metas],
                     "train_samples": int(min(sum(m["splits"]["train"]["count"] for m in metas), a.max_train or 1 << 62)),
                     "command": "python3 src/python/sgan/train.py " + " ".join(argv) + " --out OUT"})
    tensors.write(os.path.join(a.out, "sgan.bin"), "sgan-weights", weights,
                  {"architecture": arch, "training": training, "final": {**log[-1], **summary}})
    # Reference tensors: the first validation samples with fixed noise, through PyTorch.
    refs = []
    gen = torch.Generator().manual_seed(a.seed + 2)
    val = val_set["x"]
    picks = balanced_first(val_set["family"], a.references)[:a.references] if len(val) else []
    with torch.no_grad():
        for k, v in enumerate(picks):
            env, state, _, _, passability = to_inputs(val[v:v + 1])
            noise = torch.randn(env.shape, generator=gen)
            sigma = torch.from_numpy(val_set["sigma"][v:v + 1])
            out = G(env, state, noise, sigma, passability)
            refs += [(f"{k}.environment", env[0, 0].numpy()), (f"{k}.state", state[0, 0].numpy()),
                     (f"{k}.noise", noise[0, 0].numpy()), (f"{k}.output", out[0, 0].numpy())]
            if a.passability_channels:
                refs.append((f"{k}.passability", passability[0].numpy()))
            if a.scale_channels:
                refs.append((f"{k}.scale", sigma[0].numpy()))
    tensors.write(os.path.join(a.out, "reference.bin"), "sgan-reference", refs,
                  {"samples": len(picks), "weights": "sgan.bin"})
    with open(os.path.join(a.out, "metrics.json"), "w") as f:
        json.dump({"format": "miner-sgan-training-v1", "architecture": arch, "training": training, "epochs": log,
                   "selected": summary},
                  f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()
