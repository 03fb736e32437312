#!/usr/bin/env python3
"""Renders a glTF (or OBJ, or builtin:...) scene to numpy arrays and saves the colour as a PNG and the
ids and depth as .npy files beside it.

    python3 examples/python/render_gltf.py assets/hierarchy.gltf out.png --width 640 --height 480
"""

import argparse
import pathlib
import struct
import zlib

import numpy as np

import raster


def write_png(path, rgba):
    """An (H, W, 4) uint8 array as an 8-bit RGBA PNG, row 0 at the top (no imaging library needed)."""
    h, w, _ = rgba.shape
    rows = b"".join(b"\x00" + rgba[y].tobytes() for y in range(h))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(rows, 6)) + chunk(b"IEND", b"")
    pathlib.Path(path).write_bytes(png)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("output", help="PNG file; OUTPUT.ids.npy and OUTPUT.depth.npy are written too")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--camera", default="auto")
    parser.add_argument("--backend", default="auto")
    args = parser.parse_args()

    renderer = raster.Renderer(args.backend)
    frame = renderer.render(raster.Scene.load(args.scene), args.width, args.height, args.camera, msaa=4)
    write_png(args.output, frame.color)
    np.save(f"{args.output}.ids.npy", frame.ids)
    np.save(f"{args.output}.depth.npy", frame.depth)
    covered = frame.ids != raster.EMPTY_ID
    print(f"{args.output}: {frame.width}x{frame.height} on {frame.device.name}, {covered.mean():.1%} covered, "
          f"{frame.gpu_ms:.3f} ms GPU")


if __name__ == "__main__":
    main()
