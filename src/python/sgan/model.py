"""The sGAN of MINER-RRT* (paper Sec. IV-A.2, Fig. sGAN): a conditional generator that maps
noise N, the environment grid E and the state grid S to the heuristic region R, and two
conditional discriminators, one judging R against S (connectivity) and one against E
(safety).

Generator (width w, grid n^3 with n divisible by 8; "encoded at several scales", the
conditions c_k = maxpool_k([E/2, S]) enter at every scale; the 1/8 level sees the whole
grid, so every cell knows where both start and goal are; with passability_channels = 3 the
conditions are [E/2, S, Bx, By, Bz] wherever [E/2, S] stands below, B_a = 1 - P_a the dataset's
passability bits inverted: 1 where the cell's free space does not join its faces across a):
    x   = [E/2, S, N]                                   3 x n^3
    a1  = relu(conv3(x))                                w  x n^3
    a2  = relu(conv3_stride2(a1))                       2w x (n/2)^3
    a3  = relu(conv3_stride2([a2, c2]))                 4w x (n/4)^3
    a4  = relu(conv3_stride2([a3, c4]))                 4w x (n/8)^3
    m1  = relu(conv3([a4, c8, sigma]))                  4w x (n/8)^3   sigma: the scale input
    m2  = relu(conv3(m1))                               4w x (n/8)^3
    d3  = relu(conv3([up2(m2), a3, c4]))                2w x (n/4)^3   decoder with skips
    d2  = relu(conv3([up2(d3), a2, c2]))                2w x (n/2)^3
    R   = sigmoid(conv3([up2(d2), a1, E/2, S]))         1  x n^3
conv3: 3x3x3 kernel, padding 1, bias; up2: nearest-neighbour upsampling by 2; maxpool
kernel = stride. sigma (scale_channels = 3; 0 in networks trained before it) tells the
network the metric size of its cells, which the 32^3 grid over the map's bounds hides (a cell
of a 10 m indoor map and of a 200 m forest look the same): per axis a,
    sigma_a = log2(cell_a / robot_radius) / SCALE_DIVISOR,  cell_a = (bounds.max_a - bounds.min_a) / n_a,
constant over the (n/8)^3 grid of the bottleneck (whose receptive field is the whole grid, so
every cell of the decoder sees it; it costs 3 channels at 4^3, nothing next to the rest).
The C++ inference (src/miner/heuristic/sgan.hpp) runs exactly this graph
from the exported weights.

Discriminator (Sec. IV-A.2: "four volumetric convolution layers and a sigmoid"):
    D([R, c]) = sigmoid(conv4(lrelu(conv4_s2(lrelu(conv4_s2(lrelu(conv4_s2([R, c]))))))))
with 4x4x4 kernels, padding 1, stride 2 for the first three, widths 16, 32, 64, and a last
layer that maps the (n/8)^3 x 64 features to one logit per patch, averaged.
"""
import torch
import torch.nn as nn
import torch.nn.functional as F

# The generator's layers in graph order, with their input/output widths as functions of w.
# The weights file lists them in this order (export.py) and C++ checks the shapes.
# (w, s): width and scale channels.
# (w, s, p): width, scale channels and passability channels; c = 2 + p condition channels.
GENERATOR_LAYERS = [
    ("enc1", lambda w, s, p: (2 + p + 1, w), 1),
    ("enc2", lambda w, s, p: (w, 2 * w), 2),
    ("enc3", lambda w, s, p: (2 * w + 2 + p, 4 * w), 2),
    ("enc4", lambda w, s, p: (4 * w + 2 + p, 4 * w), 2),
    ("mid1", lambda w, s, p: (4 * w + 2 + p + s, 4 * w), 1),
    ("mid2", lambda w, s, p: (4 * w, 4 * w), 1),
    ("dec3", lambda w, s, p: (4 * w + 4 * w + 2 + p, 2 * w), 1),
    ("dec2", lambda w, s, p: (2 * w + 2 * w + 2 + p, 2 * w), 1),
    ("dec1", lambda w, s, p: (2 * w + w + 2 + p, 1), 1),
]

# sigma = log2(cell / robot radius) / SCALE_DIVISOR: cells of 1/16 to 16 robot radii (a 0.1 m
# voxel for a 1.6 m drone to a 5 m cell for a 0.3 m one) map into [-1, 1].
SCALE_DIVISOR = 4.0
# |sigma| <= SCALE_LIMIT (C++ kScaleLimit): a point robot (radius 0) gets +SCALE_LIMIT.
SCALE_LIMIT = 2.0


def scale_input(lo, hi, dims, robot_radius):
    """sigma (x, y, z) for a grid of dims = (nx, ny, nz) cells over the box [lo, hi]: the same
    doubles as C++'s heuristic::scale_input, rounded to float32 by the caller."""
    import math
    def one(a):
        v = math.log2((hi[a] - lo[a]) / dims[a] / robot_radius) / SCALE_DIVISOR if robot_radius > 0 else SCALE_LIMIT
        return min(max(v, -SCALE_LIMIT), SCALE_LIMIT)
    return [one(a) for a in range(3)]


class Generator(nn.Module):
    def __init__(self, width=8, scale_channels=3, passability_channels=0):
        super().__init__()
        self.width, self.scale_channels, self.passability_channels = width, scale_channels, passability_channels
        self.convs = nn.ModuleDict()
        for name, io, stride in GENERATOR_LAYERS:
            cin, cout = io(width, scale_channels, passability_channels)
            self.convs[name] = nn.Conv3d(cin, cout, 3, stride=stride, padding=1)

    def logits(self, env, state, noise, scale=None, passability=None):
        """env: E/2 in {0, 0.5, 1}; state: S in {0, 1}; noise: N(0, 1); each B x 1 x n^3;
        scale: sigma, B x scale_channels (None when scale_channels is 0); passability: the
        blocked bits 1 - P_a, a = x, y, z, B x 3 x n^3 (None when passability_channels is 0)."""
        c = self.convs
        cond1 = torch.cat([env, state] + ([passability] if self.passability_channels else []), 1)
        c2, c4, c8 = (F.max_pool3d(cond1, k) for k in (2, 4, 8))
        up = upsample2
        a1 = F.relu(c["enc1"](torch.cat([cond1, noise], 1)))
        a2 = F.relu(c["enc2"](a1))
        a3 = F.relu(c["enc3"](torch.cat([a2, c2], 1)))
        a4 = F.relu(c["enc4"](torch.cat([a3, c4], 1)))
        bottom = [a4, c8]
        if self.scale_channels:
            bottom.append(scale[:, :, None, None, None].expand(-1, -1, *a4.shape[2:]))
        m1 = F.relu(c["mid1"](torch.cat(bottom, 1)))
        m2 = F.relu(c["mid2"](m1))
        d3 = F.relu(c["dec3"](torch.cat([up(m2), a3, c4], 1)))
        d2 = F.relu(c["dec2"](torch.cat([up(d3), a2, c2], 1)))
        return c["dec1"](torch.cat([up(d2), a1, cond1], 1))

    def forward(self, env, state, noise, scale=None, passability=None):
        return torch.sigmoid(self.logits(env, state, noise, scale, passability))


def upsample2(t):
    """Nearest-neighbour upsampling by 2 in z, y and x (the same values as F.interpolate's
    "nearest"), written as a broadcast so that its gradient is a plain sum, deterministic on
    CUDA as well as on the CPU."""
    b, c, z, y, x = t.shape
    return t[:, :, :, None, :, None, :, None].expand(b, c, z, 2, y, 2, x, 2).reshape(b, c, 2 * z, 2 * y, 2 * x)


class Discriminator(nn.Module):
    def __init__(self, widths=(16, 32, 64)):
        super().__init__()
        w1, w2, w3 = widths
        self.c1 = nn.Conv3d(2, w1, 4, stride=2, padding=1)
        self.c2 = nn.Conv3d(w1, w2, 4, stride=2, padding=1)
        self.c3 = nn.Conv3d(w2, w3, 4, stride=2, padding=1)
        self.c4 = nn.Conv3d(w3, 1, 3, stride=1, padding=1)

    def logits(self, region, condition):
        x = torch.cat([region, condition], 1)
        x = F.leaky_relu(self.c1(x), 0.2)
        x = F.leaky_relu(self.c2(x), 0.2)
        x = F.leaky_relu(self.c3(x), 0.2)
        return self.c4(x).mean(dim=(1, 2, 3, 4))

    def forward(self, region, condition):
        return torch.sigmoid(self.logits(region, condition))


def continuity_loss(p, delta):
    """Paper Eq. (continuity): sum over 6-neighbour pairs of phi(|p_i - p_j| - delta) with
    phi(x) = max(0, x), on the probability grid; averaged over pairs and batch."""
    terms = []
    for axis in (2, 3, 4):
        diff = (p.narrow(axis, 1, p.shape[axis] - 1) - p.narrow(axis, 0, p.shape[axis] - 1)).abs()
        terms.append(F.relu(diff - delta).mean())
    return sum(terms) / 3.0


def safety_loss(p, solid):
    """Paper Eq. (safety): sum_i psi(p_i e_i) with psi the logistic function and e_i = 1 on
    solid cells; psi(0) = 1/2 is subtracted so free cells add nothing. Averaged over cells."""
    return (torch.sigmoid(p * solid) - 0.5).mean()
