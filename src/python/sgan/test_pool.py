"""cites: REQ-HEUR-010

train.py --pool 2 trains on the grid of half the cells per axis made from a 32^3 dataset: its E
and S must be what `miner dataset --dims 16 16 16` writes for the same maps and queries (so the
network sees at inference what it saw in training), sigma the coarse cells' size, and T the
coarse cells holding a fine T cell. Run by ctest: python3 src/python/sgan/test_pool.py MINER
[PRESET...] (default rooms and indoor, box maps with thin walls and solid blocks; the scan family,
a voxel layer, is the `long` ctest: its maps take minutes to draw under the sanitizers)."""
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import train  # noqa: E402


def dataset(miner, out, preset, dims):
    subprocess.run([miner, "dataset", "--preset", preset, "--count", "3", "--test-count", "0", "--seed", "5",
                    "--dims", *map(str, dims), "--quiet", "--out", out], check=True, stdout=subprocess.DEVNULL)


def check(miner, tmp, preset):
    fine, coarse = os.path.join(tmp, preset + "-32"), os.path.join(tmp, preset + "-16")
    dataset(miner, fine, preset, (32, 32, 32))
    dataset(miner, coarse, preset, (16, 16, 16))
    meta, pooled, sigma = train.load_split(fine, "train", 2)
    _, native, native_sigma = train.load_split(coarse, "train", 1)
    assert meta["dims"] == [16, 16, 16], meta["dims"]
    # The pooled grid has E, S and T: P is not derived from the fine cells (train.py refuses --pool
    # with a network reading P), so it is compared without the native dataset's P.
    assert pooled.shape[1] == 3 and native.shape[1] == 4, (pooled.shape, native.shape)
    assert pooled.shape == native[:, :3].shape, (pooled.shape, native.shape)
    assert (pooled[:, 0] == native[:, 0]).all(), f"{preset}: E differs from miner dataset --dims 16"
    assert (pooled[:, 1] == native[:, 1]).all(), f"{preset}: S differs from miner dataset --dims 16"
    assert np.array_equal(sigma, native_sigma), f"{preset}: sigma differs"
    _, full, _ = train.load_split(fine, "train", 1)
    n = len(full)
    want_t = full[:, 2].reshape(n, 16, 2, 16, 2, 16, 2).max(axis=(2, 4, 6))
    assert (pooled[:, 2] == want_t).all(), f"{preset}: T is not the coarse cells holding a fine T cell"
    return n, set(np.unique(pooled[:, 0]).tolist())


if __name__ == "__main__":
    miner = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        presets = sys.argv[2:] or ["rooms", "indoor"]
        results = [check(miner, tmp, p) for p in presets]
    # Each E level occurs, so the three rules were all exercised.
    levels = set().union(*(r[1] for r in results))
    assert levels == {0, 1, 2}, f"E levels seen: {levels}"
    print(f"pool: E, S and sigma of {sum(r[0] for r in results)} pooled samples equal miner dataset --dims 16's")
