"""Fixtures of the Python module's tests: backends (a missing one fails unless SR_ALLOW_MISSING_BACKENDS
lists it, as in tests/test_util.h), the `raster` command, and a PNG reader for its images."""

import os
import pathlib
import struct
import subprocess
import zlib

import numpy as np
import pytest

# The Khronos validation layer on every Vulkan device the tests open (any validation error fails the
# render that caused it), as ctest sets it and tests/test_util.cpp does for the C++ tests.
os.environ.setdefault("SR_VULKAN_VALIDATION", "1")

import raster  # noqa: E402
import raster.testing  # noqa: E402

SOURCE_DIR = pathlib.Path(os.environ.get("SR_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
RASTER_EXE = os.environ.get("SR_RASTER_EXE", str(SOURCE_DIR / "build" / "raster"))

_renderers = {}


def renderer(backend):
    """The test session's Renderer of `backend` (opened once), or a failure / skip when it is absent."""
    if backend not in _renderers:
        try:
            _renderers[backend] = raster.Renderer(backend)
        except raster.Error as error:
            if raster.testing.missing_backend_allowed(backend):
                pytest.skip(f"{backend} absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)")
            pytest.fail(f"backend {backend} is required but unavailable: {error} "
                        f"(set SR_ALLOW_MISSING_BACKENDS={backend} to allow its absence)")
    return _renderers[backend]


@pytest.fixture(params=["vulkan", "cuda"])
def backend(request):
    """Each compute backend's name, its Renderer already opened (or the test failed or skipped)."""
    renderer(request.param)
    return request.param


@pytest.fixture
def vulkan():
    return renderer("vulkan")


def run_cli(*args, check=True):
    """Runs the `raster` command; returns (returncode, stdout, stderr)."""
    done = subprocess.run([RASTER_EXE, *map(str, args)], capture_output=True, text=True)
    if check and done.returncode != 0:
        raise AssertionError(f"raster {' '.join(map(str, args))} failed: {done.stderr}")
    return done.returncode, done.stdout, done.stderr


def read_png(path):
    """An 8-bit RGBA, non-interlaced PNG (what `raster` writes through libpng) as (H, W, 4) uint8."""
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color_type, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert (depth, color_type, interlace) == (8, 6, 0)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = 4 * width
    out = np.zeros((height, stride), np.int32)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        prior = out[y - 1] if y else np.zeros(stride, np.int32)
        if f == 0:
            out[y] = line
        elif f == 2:
            out[y] = (line + prior) & 255
        else:
            # Sub, Average and Paeth depend on the pixel to the left: one pixel at a time.
            row = np.zeros(stride, np.int32)
            for x in range(stride):
                a = row[x - 4] if x >= 4 else 0
                b = prior[x]
                c = prior[x - 4] if x >= 4 else 0
                if f == 1:
                    pred = a
                elif f == 3:
                    pred = (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                row[x] = (line[x] + pred) & 255
            out[y] = row
    return out.reshape(height, width, 4).astype(np.uint8)
