#!/usr/bin/env python3
"""The cost of the Python call: Renderer.render from Python against the C++ session's own frame
(raster::Session::render timed in C++, same device, scene, camera and settings), frame by frame
alternately after warm-up frames; medians of wall-clock time, and of the GPU time each frame reports.
The issue's target: the Python call adds at most 5% or 0.1 ms, whichever is larger.

    python3 examples/python/benchmark.py --backends cuda,vulkan --json overhead.json
"""

import argparse
import json
import statistics
import sys
import time

import raster

BUNNY = "/usr/share/glmark2/models/bunny.obj"


def measure(backend, args):
    renderer = raster.Renderer(backend)
    scene = raster.Scene.load(args.scene)
    camera, settings = "auto", {"warmup": 0}
    native_settings = dict(settings, width=args.width, height=args.height)
    native = renderer._native
    for _ in range(args.warmup):
        renderer.render(scene, args.width, args.height, camera, **settings)
        native.session_frame_times(scene._native, camera, native_settings, 1)
    python_ms, cpp_ms, gpu_ms = [], [], []
    for _ in range(args.runs):
        start = time.perf_counter()
        frame = renderer.render(scene, args.width, args.height, camera, **settings)
        python_ms.append((time.perf_counter() - start) * 1e3)
        gpu_ms.append(frame.gpu_ms)
        # Freed outside the timing, as the C++ loop frees each frame before the next: holding two frames'
        # buffers at once would time the allocator, not the call.
        del frame
        cpp_ms += native.session_frame_times(scene._native, camera, native_settings, 1)
    py, cpp = statistics.median(python_ms), statistics.median(cpp_ms)
    overhead = py - cpp
    allowed = max(0.05 * cpp, 0.1)
    return {
        "backend": backend, "device": renderer.device.name, "scene": args.scene,
        "resolution": [args.width, args.height], "runs": args.runs, "warmup": args.warmup,
        "python_wall_ms": py, "cpp_session_wall_ms": cpp, "gpu_ms": statistics.median(gpu_ms),
        "overhead_ms": overhead, "overhead_percent": 100.0 * overhead / cpp, "allowed_ms": allowed,
        "within_target": overhead <= allowed,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=BUNNY)
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--warmup", type=int, default=3)
    parser.add_argument("--backends", default="cuda,vulkan")
    parser.add_argument("--json", help="write the results here")
    parser.add_argument("--check", action="store_true", help="exit 1 when a backend is over the target")
    args = parser.parse_args()

    results = []
    for backend in args.backends.split(","):
        try:
            results.append(measure(backend, args))
        except raster.Error as error:
            print(f"{backend}: {error}", file=sys.stderr)
            continue
        r = results[-1]
        print(f"{backend} ({r['device']}), {args.width}x{args.height}, median of {args.runs}: Python "
              f"{r['python_wall_ms']:.3f} ms, C++ session {r['cpp_session_wall_ms']:.3f} ms, GPU {r['gpu_ms']:.3f} ms; "
              f"overhead {r['overhead_ms']:+.3f} ms ({r['overhead_percent']:+.2f}%), allowed {r['allowed_ms']:.3f} ms: "
              f"{'ok' if r['within_target'] else 'OVER'}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=2)
    if not results:
        return 1
    return 1 if args.check and not all(r["within_target"] for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
