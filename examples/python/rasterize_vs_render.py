#!/usr/bin/env python3
"""rasterize against a render of the same cached scene: a 20,000-triangle clip-space grid at 256x256
through raster.rasterize and through Renderer.render of the scene kept on the Renderer (colour, ids and
depth, then ids alone), the three interleaved; median and min ms of 60 rounds after 5. Issue 43's lavapipe row
(docs/delivery.md):

    python3 examples/python/rasterize_vs_render.py          # the first Vulkan device: lavapipe in CI
"""
import statistics
import time

import numpy as np

import raster

r = raster.Renderer("vulkan")
# A 20,000-triangle grid mesh in clip space (100 x 100 quads), as a new user's mesh.
n = 100
y, x = np.mgrid[0:n + 1, 0:n + 1] / n * 1.8 - 0.9
pos = np.stack([x.ravel(), y.ravel(), 0.2 * np.sin(5 * x.ravel()), np.ones(x.size)], 1).astype(np.float32)
tri = []
for j in range(n):
    for i in range(n):
        v = j * (n + 1) + i
        tri += [[v, v + 1, v + n + 2], [v, v + n + 2, v + n + 1]]
tri = np.array(tri, np.int32)
gl_to_vk = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0.5, 0.5], [0, 0, 0, 1]], np.float32)
scene = raster.Scene.from_arrays(pos, tri, normals=np.zeros((len(pos), 3)))
calls = {
    "rasterize": lambda: raster.rasterize(pos, tri, (256, 256), renderer=r),
    "Renderer.render": lambda: r.render(scene, 256, 256, (np.eye(4), gl_to_vk), cull="none"),
    "render, ids only": lambda: r.render(scene, 256, 256, (np.eye(4), gl_to_vk), cull="none", outputs=("ids",)),
}
# Interleaved, one call of each per round, so that the machine's drift (2 shared cores) falls on all
# three alike: median and min of 60 rounds after 5.
ms = {name: [] for name in calls}
for round_ in range(65):
    for name, call in calls.items():
        start = time.perf_counter()
        call()
        if round_ >= 5:
            ms[name].append((time.perf_counter() - start) * 1000)
print(len(tri), "triangles, 256x256, lavapipe", r.device.driver)
for name, values in ms.items():
    print(f"{name:19s} median {statistics.median(values):.2f} ms (min {min(values):.2f})")
