"""The sGAN of MINER-RRT* (paper Sec. IV-A.2, Fig. sGAN): a conditional generator that maps
noise N, the environment grid E and the state grid S to the heuristic region R, and two
conditional discriminators, one judging R against S (connectivity) and one against E
(safety).

Generator (width w, grid n^3 with n divisible by 8; "encoded at several scales", the
conditions c_k = maxpool_k([E/2, S]) enter at every scale; the 1/8 level sees the whole
grid, so every cell knows where both start and goal are):
    x   = [E/2, S, N]                                   3 x n^3
    a1  = relu(conv3(x))                                w  x n^3
    a2  = relu(conv3_stride2(a1))                       2w x (n/2)^3
    a3  = relu(conv3_stride2([a2, c2]))                 4w x (n/4)^3
    a4  = relu(conv3_stride2([a3, c4]))                 4w x (n/8)^3
    m1  = relu(conv3([a4, c8]))                         4w x (n/8)^3
    m2  = relu(conv3(m1))                               4w x (n/8)^3
    d3  = relu(conv3([up2(m2), a3, c4]))                2w x (n/4)^3   decoder with skips
    d2  = relu(conv3([up2(d3), a2, c2]))                2w x (n/2)^3
    R   = sigmoid(conv3([up2(d2), a1, E/2, S]))         1  x n^3
conv3: 3x3x3 kernel, padding 1, bias; up2: nearest-neighbour upsampling by 2; maxpool
kernel = stride. The C++ inference (src/miner/heuristic/sgan.hpp) runs exactly this graph
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
GENERATOR_LAYERS = [
    ("enc1", lambda w: (3, w), 1),
    ("enc2", lambda w: (w, 2 * w), 2),
    ("enc3", lambda w: (2 * w + 2, 4 * w), 2),
    ("enc4", lambda w: (4 * w + 2, 4 * w), 2),
    ("mid1", lambda w: (4 * w + 2, 4 * w), 1),
    ("mid2", lambda w: (4 * w, 4 * w), 1),
    ("dec3", lambda w: (4 * w + 4 * w + 2, 2 * w), 1),
    ("dec2", lambda w: (2 * w + 2 * w + 2, 2 * w), 1),
    ("dec1", lambda w: (2 * w + w + 2, 1), 1),
]


class Generator(nn.Module):
    def __init__(self, width=8):
        super().__init__()
        self.width = width
        self.convs = nn.ModuleDict()
        for name, io, stride in GENERATOR_LAYERS:
            cin, cout = io(width)
            self.convs[name] = nn.Conv3d(cin, cout, 3, stride=stride, padding=1)

    def logits(self, env, state, noise):
        """env: E/2 in {0, 0.5, 1}; state: S in {0, 1}; noise: N(0, 1); each B x 1 x n^3."""
        c = self.convs
        cond1 = torch.cat([env, state], 1)
        c2, c4, c8 = (F.max_pool3d(cond1, k) for k in (2, 4, 8))
        up = upsample2
        a1 = F.relu(c["enc1"](torch.cat([env, state, noise], 1)))
        a2 = F.relu(c["enc2"](a1))
        a3 = F.relu(c["enc3"](torch.cat([a2, c2], 1)))
        a4 = F.relu(c["enc4"](torch.cat([a3, c4], 1)))
        m1 = F.relu(c["mid1"](torch.cat([a4, c8], 1)))
        m2 = F.relu(c["mid2"](m1))
        d3 = F.relu(c["dec3"](torch.cat([up(m2), a3, c4], 1)))
        d2 = F.relu(c["dec2"](torch.cat([up(d3), a2, c2], 1)))
        return c["dec1"](torch.cat([up(d2), a1, cond1], 1))

    def forward(self, env, state, noise):
        return torch.sigmoid(self.logits(env, state, noise))


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
