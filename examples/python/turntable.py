#!/usr/bin/env python3
"""Renders a turntable (the camera orbiting the scene) into one (frames, H, W, 4) uint8 array and saves
it with numpy. One Renderer keeps the scene on the device: only the camera changes per frame.

    python3 examples/python/turntable.py /usr/share/glmark2/models/bunny.obj turntable.npy --frames 36
"""

import argparse

import numpy as np

import raster


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("output", help=".npy file")
    parser.add_argument("--frames", type=int, default=36)
    parser.add_argument("--size", type=int, default=256, help="width and height")
    parser.add_argument("--elevation", type=float, default=20.0)
    parser.add_argument("--distance", type=float, default=2.5, help="in bounding-box diagonals")
    parser.add_argument("--backend", default="auto")
    args = parser.parse_args()

    renderer = raster.Renderer(args.backend)
    scene = raster.Scene.load(args.scene)
    lo, hi = (np.array(b) for b in scene.bounds)
    distance = args.distance * float(np.linalg.norm(hi - lo))
    frames = np.empty((args.frames, args.size, args.size, 4), np.uint8)
    for i in range(args.frames):
        azimuth = 360.0 * i / args.frames
        frame = renderer.render(scene, args.size, args.size, f"orbit:{azimuth},{args.elevation},{distance}", msaa=4)
        frames[i] = frame.color
    np.save(args.output, frames)
    print(f"{args.output}: {frames.shape} on {renderer.device.name}")


if __name__ == "__main__":
    main()
