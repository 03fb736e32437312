"""Backends agree, as a pytest file: run with `python3 -m pytest examples/python/test_backends.py`.

Every scene is rendered on CUDA and on Vulkan; ids and depth (of every sample, with MSAA) must be
identical and colour within 1. A backend that is absent fails the test unless SR_ALLOW_MISSING_BACKENDS
lists it (then the test is skipped).
"""

import pytest

import raster
import raster.testing

SCENES = ["builtin", "builtin:checker", "builtin:cutout"]


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("settings", [{}, {"msaa": 4, "aov_samples": True}, {"primitive_mode": "lines"}])
def test_cuda_and_vulkan_agree(scene, settings):
    raster.testing.assert_backends_agree(raster.Scene.load(scene), ("cuda", "vulkan"), width=64, height=48,
                                         **settings)
