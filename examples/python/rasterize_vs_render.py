#!/usr/bin/env python3
"""rasterize against a render of the same cached scene: a 20,000-triangle clip-space grid at 256x256
through raster.rasterize and through Renderer.render of the scene kept on the Renderer (colour, ids and
depth, then ids alone); median and min ms of 30 calls after 5. Issue 43's lavapipe row
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
def t(f, runs=30, warm=5):
    for _ in range(warm): f()
    ms = []
    for _ in range(runs):
        s = time.perf_counter(); f(); ms.append((time.perf_counter() - s) * 1000)
    return statistics.median(ms), min(ms)
print(len(tri), "triangles, 256x256, lavapipe", r.device.driver)
print("rasterize           median %.2f ms (min %.2f)" % t(lambda: raster.rasterize(pos, tri, (256, 256), renderer=r)))
print("Renderer.render     median %.2f ms (min %.2f)" % t(lambda: r.render(scene, 256, 256, (np.eye(4), gl_to_vk), cull="none")))
print("render, ids only    median %.2f ms (min %.2f)" % t(lambda: r.render(scene, 256, 256, (np.eye(4), gl_to_vk), cull="none", outputs=("ids",))))
