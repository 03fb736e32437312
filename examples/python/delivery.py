#!/usr/bin/env python3
"""What a Python caller receives and how fast: raster beside nvdiffrast on one mesh, camera and GPU.

Every row is wall-clock time per call from Python, the median of --runs calls after --warmup calls,
each call ending when its result is usable (torch.cuda.synchronize() for GPU tensors; a numpy array
for host ones). nvdiffrast's rows need its CUDA rasterizer (`dr.RasterizeCudaContext`) importable;
without it they are left out. The rows, as issue 43 lists them:

- rasterize, result on the GPU: nvdiffrast's torch tensor; raster's rasterize(..., on_device=True)
  output, a DeviceArray that torch.from_dlpack takes without a copy.
- rasterize, result as a host array: nvdiffrast's tensor copied out with .cpu().numpy(); raster's
  rasterize returns numpy.
- 16 views at 512 x 512 in one call, on the GPU and as host arrays.
- Renderer.render colour + ids + depth as host arrays, and left on the GPU; the frame's GPU time.
- a 1,000-frame turntable through Python with the images on the GPU: frames per second.
- ids: the pixels whose triangle differs between the two rasterizers (nvdiffrast's rules are not
  Vulkan's), of the pixels either covers.

    python3 examples/python/delivery.py --scene bunny.obj --json delivery.json
"""

import argparse
import json
import math
import statistics
import sys
import time

import numpy as np

import raster

BUNNY = "/usr/share/glmark2/models/bunny.obj"


def load_obj(path):
    """Positions (V, 3) and triangles (T, 3) of an OBJ file's v and f lines (polygons fanned)."""
    positions, triangles = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                positions.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                corners = [int(p.split("/")[0]) - 1 for p in parts[1:]]
                for k in range(1, len(corners) - 1):
                    triangles.append([corners[0], corners[k], corners[k + 1]])
    return np.array(positions, np.float32), np.array(triangles, np.int32)


def clip_positions(positions, azimuth_deg, aspect):
    """OpenGL clip-space positions of the mesh seen from `azimuth_deg` around its bounding sphere, at
    2.5 radii, 40 degrees of vertical field of view: what both rasterizers take."""
    lo, hi = positions.min(0), positions.max(0)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo)) / 2
    a = math.radians(azimuth_deg)
    eye = centre + 2.5 * radius * np.array([math.sin(a), 0.3, math.cos(a)], np.float32)
    forward = centre - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    view = np.eye(4, dtype=np.float64)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -forward
    view[:3, 3] = -view[:3, :3] @ eye
    near, far = 0.1 * radius, 10 * radius
    f = 1 / math.tan(math.radians(20))
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = f / aspect, f
    proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    proj[3, 2] = -1
    homogeneous = np.concatenate([positions, np.ones((len(positions), 1), np.float32)], 1)
    return (homogeneous @ (proj @ view).T).astype(np.float32)


def timed(call, runs, warmup, sync=None):
    """Median, min and max ms of `call` over `runs` calls after `warmup`, each followed by `sync`."""
    for _ in range(warmup):
        call()
        if sync:
            sync()
    ms = []
    for _ in range(runs):
        start = time.perf_counter()
        call()
        if sync:
            sync()
        ms.append((time.perf_counter() - start) * 1000)
    return {"median_ms": statistics.median(ms), "min_ms": min(ms), "max_ms": max(ms), "runs": runs}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", default=BUNNY, help="an OBJ mesh (default: glmark2's bunny)")
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--runs", type=int, default=30)
    parser.add_argument("--warmup", type=int, default=5)
    parser.add_argument("--turntable", type=int, default=1000, help="frames of the on-device turntable")
    parser.add_argument("--backend", default="cuda")
    parser.add_argument("--json", help="write the rows here too")
    args = parser.parse_args()

    positions, tri = load_obj(args.scene)
    res = (args.height, args.width)
    pos = clip_positions(positions, 30.0, args.width / args.height)
    views = np.stack([clip_positions(positions, 360.0 * k / 16, 1.0) for k in range(16)])
    renderer = raster.Renderer(args.backend)
    rows = {"device": renderer.device.name, "driver": renderer.device.driver, "backend": args.backend,
            "scene": args.scene, "triangles": int(len(tri)), "resolution": f"{args.width}x{args.height}"}
    print(f"{renderer.device.name} ({renderer.device.driver}), {len(tri)} triangles, {args.width}x{args.height}")

    def row(name, result):
        rows[name] = result
        print(f"{name:58s} {result['median_ms']:9.3f} ms (min {result['min_ms']:.3f})")

    torch = dr = None
    try:
        import torch
        import nvdiffrast.torch as dr
    except ImportError as error:
        print(f"nvdiffrast rows left out: {error}")
    on_gpu = args.backend == "cuda"

    # ---- rasterize, one view ------------------------------------------------------------------------
    if dr is not None:
        ctx = dr.RasterizeCudaContext()
        tpos = torch.from_numpy(pos).cuda()[None]
        ttri = torch.from_numpy(tri).cuda()
        sync = torch.cuda.synchronize
        row("nvdiffrast rasterize, on the GPU", timed(lambda: dr.rasterize(ctx, tpos, ttri, res)[0], args.runs, args.warmup, sync))
        row("nvdiffrast rasterize, host array", timed(lambda: dr.rasterize(ctx, tpos, ttri, res)[0].cpu().numpy(), args.runs, args.warmup))
    if on_gpu:
        row("raster rasterize, on the GPU", timed(lambda: raster.rasterize(pos, tri, res, renderer=renderer, on_device=True), args.runs, args.warmup))
        if torch is not None:
            # nvdiffrast's own inputs: torch tensors on the GPU in, a torch tensor on the GPU out.
            row("raster rasterize, torch on the GPU in and out", timed(lambda: raster.rasterize(tpos, ttri, res, renderer=renderer), args.runs, args.warmup))
            row("raster rasterize, torch on the GPU in, host array out", timed(lambda: raster.rasterize(tpos, ttri, res, renderer=renderer, on_device=False), args.runs, args.warmup))
    row("raster rasterize, host array", timed(lambda: raster.rasterize(pos, tri, res, renderer=renderer), args.runs, args.warmup))

    # ---- interpolate at 1080p, on the GPU -------------------------------------------------------------
    if on_gpu and dr is not None:
        tattr = torch.from_numpy(np.ascontiguousarray(positions[:, :3], np.float32)).cuda()
        nv_rast = dr.rasterize(ctx, tpos, ttri, res)[0]
        our_rast = raster.rasterize(tpos, ttri, res, renderer=renderer)
        row("nvdiffrast interpolate (3 channels), on the GPU", timed(lambda: dr.interpolate(tattr, nv_rast, ttri)[0], args.runs, args.warmup, sync))
        row("raster interpolate (3 channels), torch on the GPU in and out", timed(lambda: raster.interpolate(tattr, our_rast, ttri, renderer=renderer), args.runs, args.warmup))
        same = np.array_equal(raster.interpolate(tattr, our_rast, ttri, renderer=renderer).cpu().numpy(),
                              raster.interpolate(tattr.cpu().numpy(), our_rast.cpu().numpy(), tri))
        rows["interpolate_gpu_equals_host"] = bool(same)
        print(f"interpolate on the GPU equals the host's byte for byte: {same}")

    # ---- 16 views at 512 x 512 ----------------------------------------------------------------------
    if dr is not None:
        tviews = torch.from_numpy(views).cuda()
        row("nvdiffrast 16 views 512x512, on the GPU", timed(lambda: dr.rasterize(ctx, tviews, ttri, (512, 512))[0], args.runs, args.warmup, sync))
        row("nvdiffrast 16 views 512x512, host arrays", timed(lambda: dr.rasterize(ctx, tviews, ttri, (512, 512))[0].cpu().numpy(), args.runs, args.warmup))
    if on_gpu:
        row("raster 16 views 512x512, on the GPU", timed(lambda: raster.rasterize(views, tri, (512, 512), renderer=renderer, on_device=True), args.runs, args.warmup))
        if torch is not None:
            row("raster 16 views 512x512, torch on the GPU in and out", timed(lambda: raster.rasterize(tviews, ttri, (512, 512), renderer=renderer), args.runs, args.warmup))
            row("raster 16 views 512x512, torch on the GPU in, host arrays out", timed(lambda: raster.rasterize(tviews, ttri, (512, 512), renderer=renderer, on_device=False), args.runs, args.warmup))
            got = raster.rasterize(tviews, ttri, (512, 512), renderer=renderer)
            same = isinstance(got, torch.Tensor) and got.is_cuda and np.array_equal(
                got.cpu().numpy(), raster.rasterize(views, tri, (512, 512), renderer=renderer))
            rows["torch_views_equal_host"] = bool(same)
            print(f"16 views, torch in and out, equal the host arrays byte for byte: {same}")
    row("raster 16 views 512x512, host arrays", timed(lambda: raster.rasterize(views, tri, (512, 512), renderer=renderer), args.runs, args.warmup))

    # ---- ids beside nvdiffrast's --------------------------------------------------------------------
    ours = raster.rasterize(pos, tri, res, renderer=renderer)[0]
    if dr is not None:
        theirs = dr.rasterize(ctx, tpos, ttri, res)[0][0].cpu().numpy()
        covered = (ours[..., 3] > 0) | (theirs[..., 3] > 0)
        differ = covered & (ours[..., 3] != theirs[..., 3])
        rows["ids"] = {"covered_pixels": int(covered.sum()), "differing_pixels": int(differ.sum()),
                       "differing_fraction": float(differ.sum() / max(1, covered.sum()))}
        print(f"ids: {int(differ.sum())} of {int(covered.sum())} covered pixels differ from nvdiffrast's "
              f"({100 * differ.sum() / max(1, covered.sum()):.2f}%)")

    # ---- Renderer.render: colour + ids + depth ------------------------------------------------------
    scene = raster.Scene.from_arrays(positions, tri)
    camera = "orbit:30,17,2.5r"
    frame = renderer.render(scene, args.width, args.height, camera)
    rows["frame_gpu_ms"] = frame.gpu_ms
    print(f"{'Renderer.render, the GPU frame':58s} {frame.gpu_ms:9.3f} ms")
    row("Renderer.render colour + ids + depth, host arrays", timed(lambda: renderer.render(scene, args.width, args.height, camera), args.runs, args.warmup))
    # Many cameras in one call against a call per camera: 16 frames of an orbit.
    orbit = [f"orbit:{22.5 * k},17,2.5r" for k in range(16)]
    row("16 frames, Renderer.render per camera, host arrays", timed(lambda: [renderer.render(scene, args.width, args.height, c) for c in orbit], args.runs // 3, 2))
    row("16 frames, Renderer.render_many, host arrays", timed(lambda: renderer.render_many(scene, args.width, args.height, orbit), args.runs // 3, 2))
    many = renderer.render_many(scene, args.width, args.height, orbit)
    same = all(np.array_equal(many[n][k], getattr(renderer.render(scene, args.width, args.height, c), n))
               for k, c in enumerate(orbit) for n in ("color", "ids", "depth"))
    rows["render_many_equals_render"] = bool(same)
    print(f"render_many equals a render per camera byte for byte: {same}")
    if on_gpu:
        row("16 frames, Renderer.render per camera, on the GPU", timed(lambda: [renderer.render(scene, args.width, args.height, c, on_device=True) for c in orbit], args.runs // 3, 2))
        row("16 frames, Renderer.render_many, on the GPU", timed(lambda: renderer.render_many(scene, args.width, args.height, orbit, on_device=True), args.runs // 3, 2))
    if on_gpu:
        row("Renderer.render colour + ids + depth, on the GPU", timed(lambda: renderer.render(scene, args.width, args.height, camera, on_device=True), args.runs, args.warmup))
        if torch is not None:
            gpu = renderer.render(scene, args.width, args.height, camera, on_device=True)
            host = renderer.render(scene, args.width, args.height, camera)
            same = all(np.array_equal(torch.from_dlpack(getattr(gpu, n)).cpu().numpy(), getattr(host, n))
                       for n in ("color", "ids", "depth"))
            rows["device_equals_host"] = same
            print(f"on-device images equal the host's byte for byte: {same}")
        # A turntable through Python, its images left on the GPU.
        start = time.perf_counter()
        for k in range(args.turntable):
            renderer.render(scene, args.width, args.height, f"orbit:{360.0 * k / args.turntable},17,2.5r", on_device=True)
        seconds = time.perf_counter() - start
        rows["turntable_on_gpu_fps"] = args.turntable / seconds
        print(f"{'turntable, ' + str(args.turntable) + ' frames on the GPU':58s} {args.turntable / seconds:9.1f} frames/s")

    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=2)


if __name__ == "__main__":
    sys.exit(main())
