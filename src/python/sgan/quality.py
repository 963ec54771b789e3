"""Connectivity and safety of a region, exactly as REQ-HEUR-004 defines them (the C++ side
is src/miner/heuristic/grid.hpp): safe = no solid cell (E == 2) in the region; connected =
the start and goal cells are in the region and joined by a 26-connected chain of its cells.
The start and goal cells are the centres of the two 3x3x3 cubes of S."""
import numpy as np
from scipy import ndimage


def endpoints(state):
    """Centres of the S cubes: cells whose whole 3x3x3 neighbourhood (clipped) is in S and
    that are farthest apart; the cube centres are exactly the cells with a full clipped cube."""
    cells = np.argwhere(state > 0)
    if len(cells) == 0:
        return None, None
    # A cube centre c has all of c + {-1,0,1}^3 (inside the grid) in S; cubes at least 3
    # cells apart (the dataset's separation) give exactly two such cells far apart.
    full = [tuple(c) for c in cells if _full_cube(state, c)]
    if not full:
        return tuple(cells[0]), tuple(cells[-1])
    far = max(((a, b) for a in full for b in full), key=lambda ab: sum((x - y) ** 2 for x, y in zip(*ab)))
    return far


def _full_cube(state, c):
    lo = np.maximum(c - 1, 0)
    hi = np.minimum(c + 2, state.shape)
    return bool(state[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]].all())


# 26-connectivity: cells sharing a face, an edge or a corner.
NEIGHBOURS_26 = np.ones((3, 3, 3), dtype=bool)


def connected(region, a, b):
    """True when cells a and b are in the region and one 26-connected component holds both."""
    if not region[a] or not region[b]:
        return False
    labels, _ = ndimage.label(region, structure=NEIGHBOURS_26)
    return bool(labels[a] == labels[b])


def connected_and_safe(region, env, state):
    a, b = endpoints(state)
    conn = a is not None and connected(region, a, b)
    safe = not bool((region & (env == 2)).any())
    return int(conn), int(safe)
