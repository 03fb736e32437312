#!/usr/bin/env python3
"""Arrays in, ids and depth out: a torus generated with numpy, rendered with an explicit camera
(view and projection matrices), its triangle ids and depth saved as .npz.

    python3 examples/python/arrays.py torus.npz --size 256
"""

import argparse

import numpy as np

import raster


def torus(major=1.0, minor=0.35, rings=48, sides=24):
    """Positions (N, 3) float32 and counter-clockwise triangles (T, 3) int32 of a torus around y."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, rings, endpoint=False),
                       np.linspace(0, 2 * np.pi, sides, endpoint=False), indexing="ij")
    r = major + minor * np.cos(v)
    positions = np.stack([r * np.cos(u), minor * np.sin(v), r * np.sin(u)], -1).reshape(-1, 3)
    i = np.arange(rings * sides).reshape(rings, sides)
    a, b = i, np.roll(i, -1, axis=0)
    c, d = np.roll(i, -1, axis=1), np.roll(b, -1, axis=1)
    triangles = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)]).reshape(-1, 3)
    return positions.astype(np.float32), triangles.astype(np.int32)


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """A view matrix (world to view, the camera looking down -z)."""
    f = np.subtract(target, eye) / np.linalg.norm(np.subtract(target, eye))
    s = np.cross(f, up) / np.linalg.norm(np.cross(f, up))
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ np.asarray(eye)
    return m


def perspective(fov_y_degrees, aspect, near, far):
    """A projection in Vulkan's conventions: depth 0..1 with the near plane at 0, NDC y = -1 at the top."""
    t = 1.0 / np.tan(np.radians(fov_y_degrees) / 2)
    m = np.zeros((4, 4))
    m[0, 0] = t / aspect
    m[1, 1] = -t  # Vulkan's y points down the image
    m[2, 2] = far / (near - far)
    m[2, 3] = near * far / (near - far)
    m[3, 2] = -1.0
    return m


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", help=".npz with ids (uint32) and depth (float32)")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--backend", default="auto")
    args = parser.parse_args()

    positions, triangles = torus()
    scene = raster.Scene.from_arrays(positions, triangles)
    camera = (look_at((0.0, 2.0, 3.0), (0.0, 0.0, 0.0)), perspective(45.0, 1.0, 0.5, 10.0))
    frame = raster.Renderer(args.backend).render(scene, args.size, args.size, camera)
    np.savez(args.output, ids=frame.ids, depth=frame.depth)
    covered = frame.ids != raster.EMPTY_ID
    print(f"{args.output}: {len(triangles)} triangles, {len(np.unique(frame.ids[covered]))} visible, "
          f"{covered.mean():.1%} of the pixels, depth {frame.depth[covered].min():.4f}..{frame.depth[covered].max():.4f}")


if __name__ == "__main__":
    main()
