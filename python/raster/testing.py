"""Helpers for tests (pytest or any other runner): do backends, or two frames, agree?

A backend that does not open fails the check, unless the environment variable
SR_ALLOW_MISSING_BACKENDS lists it (comma-separated, e.g. "cuda"), as in this project's own tests;
then it is left out, and with fewer than two backends left the check is skipped (pytest.skip).
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence

from . import Camera, Error, Frame, Renderer, Scene, _shared_renderer, compare

__all__ = ["assert_backends_agree", "assert_frames_agree", "missing_backend_allowed"]


def missing_backend_allowed(backend: str) -> bool:
    """Whether SR_ALLOW_MISSING_BACKENDS lists `backend` (its absence is then not a failure)."""
    allowed = os.environ.get("SR_ALLOW_MISSING_BACKENDS", "")
    return backend in [b.strip() for b in allowed.split(",")]


def assert_frames_agree(reference: Frame, frame: Frame, *, color_tolerance: int = 1,
                        depth_tolerance: float = 0.0, max_id_mismatches: int = 0,
                        label: str = "") -> Dict[str, Any]:
    """Fails (AssertionError with ``raster compare``'s report) unless the ids and depth of the two
    frames (every sample's too when both have them) agree within the tolerances (by default exactly)
    and their colour within `color_tolerance` 8-bit units. Returns the comparison (raster.compare)."""
    report = compare(reference, frame, what="both", tolerance=color_tolerance,
                     depth_tolerance=depth_tolerance, max_id_mismatches=max_id_mismatches)
    if not report["passed"]:
        raise AssertionError(f"frames differ{' (' + label + ')' if label else ''}:\n{report['text']}")
    return report


def assert_backends_agree(scene: Scene, backends: Sequence[str] = ("cuda", "vulkan"), *, width: int = 64,
                          height: int = 64, camera: Camera = "auto", color_tolerance: int = 1,
                          depth_tolerance: float = 0.0, max_id_mismatches: int = 0,
                          renderers: Optional[Dict[str, Renderer]] = None,
                          **settings: Any) -> List[Dict[str, Any]]:
    """Renders `scene` on each backend (with the same camera and settings) and checks every frame
    against the first backend's with assert_frames_agree: ids and depth identical (every sample's with
    aov_samples=True), colour within `color_tolerance`. Returns the comparisons.

    renderers: Renderers to use by backend name (others are opened once per process and kept).
    """
    if len(backends) < 2:
        raise Error("assert_backends_agree: name at least two backends")
    frames = []
    for backend in backends:
        try:
            renderer = (renderers or {}).get(backend) or _shared_renderer(backend)
        except Error as error:
            if missing_backend_allowed(backend):
                continue
            raise AssertionError(f"backend {backend} is required but unavailable: {error} (set "
                                 f"SR_ALLOW_MISSING_BACKENDS={backend} to allow its absence)") from None
        frames.append((backend, renderer.render(scene, width, height, camera, **settings)))
    if len(frames) < 2:
        import pytest

        pytest.skip(f"fewer than two of {', '.join(backends)} present (SR_ALLOW_MISSING_BACKENDS)")
    reference_backend, reference = frames[0]
    return [assert_frames_agree(reference, frame, color_tolerance=color_tolerance,
                                depth_tolerance=depth_tolerance, max_id_mismatches=max_id_mismatches,
                                label=f"{reference_backend} vs {backend}")
            for backend, frame in frames[1:]]
