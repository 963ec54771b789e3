"""cites: REQ-HEUR-010 REQ-HEUR-013 REQ-HEUR-015

The training symmetries map a query to a query of the same
metric geometry. Run by ctest: python3 src/python/sgan/test_augment.py

For each symmetry code, a grid holding two marked voxels p and q (the start and goal of a
query) and sigma (the cells' log2 metric size per axis) goes through train.augment; the marked
voxels are found again and the metric distance |p - q| (cell counts times 2^sigma per axis)
must be unchanged: a path of length L stays a path of length L, which is why the A* target
stays optimal. Every code must also give a different grid (no symmetry counted twice). The
passability bits (channel P, one per axis) must follow the axes: a cell passable across x only
is, after the symmetry, passable across the axis that x became (the one sigma_x went to)."""
import os
import sys

import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import train  # noqa: E402


def metric_distance(grid, sigma):
    """grid uint8 [1, 3, n, n, n]: channel 1 holds 1 at p and 2 at q; distance in metres."""
    s = grid[0, 1]
    p = (s == 1).nonzero()[0].double()  # (z, y, x)
    q = (s == 2).nonzero()[0].double()
    cell = torch.pow(2.0, sigma.double())  # (x, y, z)
    d = (p - q).flip(0) * cell
    return float(d.norm())


def check(cube, codes, swap_xy):
    n = 8
    gen = torch.Generator().manual_seed(5)
    grid = torch.randint(0, 3, (1, 4, n, n, n), generator=gen, dtype=torch.uint8)
    grid[0, 1] = 0
    grid[0, 1, 1, 2, 6] = 1  # p at x=6, y=2, z=1
    grid[0, 1, 5, 7, 0] = 2  # q at x=0, y=7, z=5
    grid[0, 3] = 0
    grid[0, 3, 1, 2, 6] = 1  # p passable across x only
    grid[0, 3, 5, 7, 0] = 6  # q across y and z
    sigma = torch.tensor([[0.3, -1.1, 1.7]])
    want = metric_distance(grid, sigma)
    seen = set()
    for c in range(codes):
        code = torch.tensor([c])
        out, out_sigma = train.augment(grid.clone(), sigma.clone(), code, swap_xy, cube)
        got = metric_distance(out, out_sigma)
        assert abs(got - want) <= 1e-12 * want, f"code {c}: distance {got} != {want}"
        assert sorted(out[:, :3].flatten().tolist()) == sorted(grid[:, :3].flatten().tolist()), \
            f"code {c}: not a permutation"
        s = out[0, 1]
        new_axis = [int((out_sigma[0] == sigma[0, a]).nonzero()[0]) for a in range(3)]  # old axis a -> new
        p_bits = int(out[0, 3][s == 1][0])
        q_bits = int(out[0, 3][s == 2][0])
        assert p_bits == 1 << new_axis[0], f"code {c}: P at p is {p_bits}, x went to axis {new_axis[0]}"
        assert q_bits == (1 << new_axis[1]) | (1 << new_axis[2]), f"code {c}: P at q is {q_bits}"
        assert int(out[0, 3].count_nonzero()) == 2, f"code {c}: P bits appeared elsewhere"
        key = out.numpy().tobytes()
        assert key not in seen, f"code {c}: the same grid as an earlier code"
        seen.add(key)
    return len(seen)


if __name__ == "__main__":
    assert check(cube=True, codes=48, swap_xy=True) == 48
    assert check(cube=False, codes=8, swap_xy=True) == 8
    assert check(cube=False, codes=4, swap_xy=False) == 4
    print("augment: 48 cube symmetries and 8 square ones keep the query's metric length and turn P's bits with the axes")
