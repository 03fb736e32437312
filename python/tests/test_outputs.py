"""The `raster` command's colour outputs as an ML pipeline reads them: the .npy through numpy.load (and
memory-mapped, which needs the header's 64-byte alignment) equals the PNG of the same render, whatever the
PNG encoder's speed."""

import numpy as np
import pytest

from conftest import read_png, run_cli

W, H = 40, 24
RENDER = ("render", "builtin", "--backend", "vulkan", "--width", W, "--height", H, "-q")


@pytest.mark.parametrize("speed", ["fast", "default", "small"])
def test_npy_loads_in_numpy_and_equals_the_png(vulkan, tmp_path, speed):
    run_cli(*RENDER, "-o", tmp_path / "frame.npy")
    run_cli(*RENDER, "-o", tmp_path / "frame.png", "--png-compression", speed)
    array = np.load(tmp_path / "frame.npy", allow_pickle=False)
    assert array.shape == (H, W, 4) and array.dtype == np.uint8
    np.testing.assert_array_equal(array, read_png(tmp_path / "frame.png"))
    mapped = np.load(tmp_path / "frame.npy", mmap_mode="r")
    assert mapped.offset % 64 == 0
    np.testing.assert_array_equal(mapped, array)
    # A frame with something in it: the scene over the background.
    assert len(np.unique(array.reshape(-1, 4), axis=0)) > 2


def test_other_extensions_are_refused(vulkan, tmp_path):
    code, _, err = run_cli(*RENDER, "-o", tmp_path / "frame.bmp", check=False)
    assert code == 2
    assert err.count("\n") == 1 and "must end in .png or .npy" in err
    assert not list(tmp_path.iterdir())
