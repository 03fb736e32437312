#!/usr/bin/env python3
"""The cost of the Python call: Renderer.render from Python against the C++ session's own frame
(raster::Session::render timed in C++, same device, scene, camera and settings), frame by frame
alternately after warm-up frames; medians of wall-clock time, and of the GPU time each frame reports.
The issue's target: the Python call adds at most 5% or 0.1 ms, whichever is larger.

With --alternate SCENE2, also the price of two scenes on one renderer: their sessions share the device's
buffers (docs/python.md, "Several scenes"), so a frame of the first scene after a frame of the second
uploads the first scene again. Medians of the first scene's frames with and without one of SCENE2's
between each, and whether those frames' images equal the ones drawn without it.

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
    alternate = measure_alternate(renderer, scene, args) if args.alternate else {}
    return alternate | {
        "backend": backend, "device": renderer.device.name, "scene": args.scene,
        "resolution": [args.width, args.height], "runs": args.runs, "warmup": args.warmup,
        "python_wall_ms": py, "cpp_session_wall_ms": cpp, "gpu_ms": statistics.median(gpu_ms),
        "overhead_ms": overhead, "overhead_percent": 100.0 * overhead / cpp, "allowed_ms": allowed,
        "within_target": overhead <= allowed,
    }


def measure_alternate(renderer, scene, args):
    """The first scene's frames alone, then each after a frame of the second scene (timed apart)."""
    other = raster.Scene.load(args.alternate)
    size = (args.width, args.height)
    reference = renderer.render(scene, *size, "auto", warmup=0)
    alone_ms, after_ms, equal = [], [], True
    for _ in range(args.runs):
        start = time.perf_counter()
        renderer.render(scene, *size, "auto", warmup=0)
        alone_ms.append((time.perf_counter() - start) * 1e3)
    for _ in range(args.runs):
        renderer.render(other, *size, "auto", warmup=0)
        start = time.perf_counter()
        frame = renderer.render(scene, *size, "auto", warmup=0)
        after_ms.append((time.perf_counter() - start) * 1e3)
        equal = equal and bool((frame.ids == reference.ids).all() and (frame.color == reference.color).all())
    return {"alternate_scene": args.alternate, "alone_wall_ms": statistics.median(alone_ms),
            "after_other_scene_wall_ms": statistics.median(after_ms), "alternate_frames_equal": equal}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=BUNNY)
    parser.add_argument("--width", type=int, default=1920)
    parser.add_argument("--height", type=int, default=1080)
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--warmup", type=int, default=3)
    parser.add_argument("--backends", default="cuda,vulkan")
    parser.add_argument("--alternate", help="a second scene drawn between frames of the first")
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
        if args.alternate:
            print(f"  {args.scene} alone {r['alone_wall_ms']:.3f} ms, after a frame of {args.alternate} "
                  f"{r['after_other_scene_wall_ms']:.3f} ms; frames equal: {r['alternate_frames_equal']}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=2)
    if not results:
        return 1
    return 1 if args.check and not all(r["within_target"] for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
