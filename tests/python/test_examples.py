"""The examples' own promises: the data set is deterministic from its seed."""
import os
import sys

import numpy as np

from conftest import SOURCE_DIR

sys.path.insert(0, os.path.join(SOURCE_DIR, "examples", "python"))
import dam_break_dataset  # noqa: E402


def test_the_data_set_is_the_same_for_the_same_seed_and_any_thread_count(tmp_path):
    a, meta_a = dam_break_dataset.generate(7, 2, 40, 10, str(tmp_path / "a"), threads=1, radius=0.01)
    b, meta_b = dam_break_dataset.generate(7, 2, 40, 10, str(tmp_path / "b"), threads=2, radius=0.01)
    c, _ = dam_break_dataset.generate(8, 2, 40, 10, str(tmp_path / "c"), threads=2, radius=0.01)
    assert a.keys() == b.keys() and meta_a == meta_b
    for k in a:
        assert a[k].tobytes() == b[k].tobytes(), k
    assert a["positions_0"].shape != c["positions_0"].shape or not np.array_equal(a["positions_0"], c["positions_0"])
    x = a["positions_0"]
    assert x.dtype == np.float32 and x.shape[0] == 5 and x.shape[2] == 2
    assert not np.array_equal(x[0], x[-1])  # the water moved
    with np.load(tmp_path / "a" / "trajectories.npz") as f:
        assert np.array_equal(f["positions_1"], a["positions_1"])
    assert meta_a["sequence_length"] == 5 and meta_a["dim"] == 2
