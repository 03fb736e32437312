"""raster: one exact software rasterizer on CUDA and Vulkan compute, from Python.

numpy in, numpy out::

    import raster
    r = raster.Renderer()                          # CUDA if present, else Vulkan (a GPU, else lavapipe)
    scene = raster.Scene.load("model.gltf")        # or Scene.from_arrays(positions, indices, ...)
    frame = r.render(scene, 640, 480, camera="orbit:30,20,3", msaa=4)
    frame.color    # (480, 640, 4) uint8 sRGB, row 0 the top row (as in the PNG)
    frame.ids      # (480, 640) uint32 triangle ids, raster.EMPTY_ID where empty
    frame.depth    # (480, 640) float32 window depth 0..1, 1 where empty

nvdiffrast's forward pass: ``raster.rasterize(pos, tri, (h, w))`` and ``raster.interpolate``.
Comparisons: ``raster.compare`` and ``raster.testing.assert_backends_agree``.

Every function that fails on bad input or a failing device raises :class:`raster.Error`, whose text
is the one line the ``raster`` command prints for the same problem. The conventions (y direction, ids,
depth, pixel centres) and how they differ from nvdiffrast's and PyTorch3D's are in docs/python.md.
"""

from __future__ import annotations

import difflib
import functools
import json
import os
import numbers
import threading
import warnings
import weakref
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _raster

__all__ = [
    "EMPTY_ID",
    "OUTPUTS",
    "SETTINGS",
    "DeviceArray",
    "DeviceInfo",
    "Error",
    "Frame",
    "RasterWarning",
    "Renderer",
    "Scene",
    "compare",
    "devices",
    "interpolate",
    "rasterize",
    "version",
]

DeviceArray = _raster.DeviceArray
DeviceArray.__doc__ = (
    "An image in GPU memory (Renderer.render(on_device=True)): shape, typestr ('<u1', '<u4', '<f4'), "
    "device (the CUDA ordinal), data_ptr; CUDA libraries take it without a copy through DLPack "
    "(torch.from_dlpack(a), jax.dlpack.from_dlpack(a)) or __cuda_array_interface__ (cupy.asarray(a), "
    "numba). It keeps its frame's memory alive, and is whole when render returns."
)
DeviceArray.__module__ = "raster"

Error = _raster.Error
Error.__doc__ = (
    "A raster failure: bad input (a file, an array, a setting) or a device that failed. str(error) "
    "is the one-line message the raster command prints for the same problem."
)
Error.__module__ = "raster"


class RasterWarning(UserWarning):
    """Part of the input was dropped or drawn otherwise than asked (a triangle with an index out of
    range, a texture that cannot load): the line ``raster render`` prints after "warning: "."""


RasterWarning.__module__ = "raster"


def _warn(lines: Sequence[str]) -> None:
    for line in lines:
        # stacklevel 3: the caller of the public function that made the scene or frame.
        warnings.warn(line, RasterWarning, stacklevel=3)


def _shown(value: Any) -> str:
    """A value the caller gave, for a one-line message: its repr, cut to a readable length."""
    text = repr(value) if not isinstance(value, np.ndarray) else (
        f"an array of {value.dtype} {tuple(value.shape)}")
    text = " ".join(text.split())
    return text if len(text) <= 80 else text[:77] + "..."


def _real_array(value: Any, what: str, dtype: Any = np.float32) -> np.ndarray:
    """`value` as a C-contiguous array of `dtype`, or raster.Error unless it holds real numbers (integers or
    floats: not bools, complex numbers, strings or objects)."""
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as error:
        raise Error(f"{what} must be an array of numbers, not {_shown(value)} ({error})") from None
    if a.dtype.kind not in "iuf":
        raise Error(f"{what} must hold real numbers, not {a.dtype} ({_shown(value)})")
    return np.ascontiguousarray(a, dtype=dtype)


def _finite(a: np.ndarray, what: str) -> None:
    if a.size and not np.isfinite(a).all():
        row = int(np.argwhere(~np.isfinite(a))[0][0])
        raise Error(f"{what} has a non-finite value in row {row}: {_shown(a[row].tolist())}")


EMPTY_ID = 0xFFFFFFFF
"""The id of a pixel (or sample) no primitive covers (Frame.ids, Frame.sample_ids)."""

SETTINGS: List[Dict[str, Any]] = json.loads(_raster.settings_schema())
"""The settings schema: one dict per render setting (name, key, type, default, choices or range,
help), as ``raster settings --format json`` prints it. Renderer.render takes each ``key`` as a
keyword argument (width, height and camera are its positional parameters)."""

# Renderer.render's own defaults where they differ from the schema's: a session renders many frames, so
# the untimed warm-up frame the command line renders first is left to the caller.
_SESSION_DEFAULTS = {"warmup": 0}
# Settings that are Renderer.render's parameters rather than keywords.
_PARAMETERS = ("width", "height", "camera")

OUTPUTS = ("color", "ids", "depth")
"""The images a Frame can hold (Renderer.render's ``outputs``; all of them by default)."""
# The library's raster::Output bits of each.
_OUTPUT_BITS = {"color": 1, "ids": 2, "depth": 4}


def version() -> str:
    """The library's version, "MAJOR.MINOR.PATCH"."""
    return _raster.version()


@dataclass(frozen=True)
class DeviceInfo:
    """One device: ``Renderer(backend, index)`` opens it.

    backend: "cuda" or "vulkan"; index: the device's index within its backend; name: as the API
    reports it; driver: driver or runtime version; cpu: a CPU implementation (Mesa lavapipe).
    """

    backend: str
    index: int
    name: str
    driver: str
    cpu: bool

    @property
    def kind(self) -> str:
        """"cpu" or "gpu"."""
        return "cpu" if self.cpu else "gpu"


def _device(info: Dict[str, Any]) -> DeviceInfo:
    return DeviceInfo(info["backend"], info["index"], info["name"], info["driver"], info["cpu"])


def devices() -> List[DeviceInfo]:
    """Every device this machine offers: each CUDA GPU, then each Vulkan device the pipeline can use
    (GPUs first, CPU implementations such as lavapipe last). A backend that is absent contributes
    nothing, so the list may be empty."""
    return [_device(d) for d in _raster.devices()]


class Scene:
    """A scene in memory (not yet on a device): meshes, materials, textures, cameras.

    Make one with :meth:`Scene.load` or :meth:`Scene.from_arrays`; a Renderer uploads it once and keeps
    it on its device for every later render of the same Scene object.
    """

    __slots__ = ("_native",)

    def __init__(self, native: Any) -> None:
        self._native = native

    @staticmethod
    def load(path: Union[str, os.PathLike]) -> "Scene":
        """A .gltf/.glb or .obj file, or a built-in scene ("builtin", "builtin:dense", "builtin:huge",
        "builtin:checker", "builtin:cutout", "builtin:lowpoly"), with the command line's checks:
        broken parts are dropped with a warning on stderr, a scene with nothing to draw raises
        raster.Error."""
        if not isinstance(path, (str, os.PathLike)):
            raise Error(f"Scene.load: path must be a str or os.PathLike, not {_shown(path)}")
        native = _raster.Scene.load(os.fspath(path))
        _warn(native.warnings)
        return Scene(native)

    @staticmethod
    def from_arrays(
        positions: np.ndarray,
        indices: Optional[np.ndarray] = None,
        normals: Optional[np.ndarray] = None,
        uv: Optional[np.ndarray] = None,
        colors: Optional[np.ndarray] = None,
        texture: Optional[np.ndarray] = None,
        *,
        lines: Optional[np.ndarray] = None,
        points: Optional[np.ndarray] = None,
        base_color: Sequence[float] = (1.0, 1.0, 1.0, 1.0),
        double_sided: bool = False,
        texture_srgb: bool = True,
    ) -> "Scene":
        """A scene of one mesh from numpy arrays, with the loaders' checks and errors.

        positions: (N, 3) float32 world-space points (other float types are converted), or (N, 4)
            homogeneous points (x, y, z, w). Non-finite vertices drop their primitives with a warning.

        Every array may also be a GPU array (torch, CuPy: anything with __cuda_array_interface__); it is
        copied to the host once, through its own library. A Scene is the host's description of the
        mesh (its checks, normals, bounds and clusters are computed there; a Renderer uploads it once).
        Positions that change every frame on the GPU go to rasterize instead, which reads them in place.
        indices: (T, 3) int32 or uint32 vertex indices, counter-clockwise in front; a triangle with an
            index out of range is dropped with a warning (as the loaders do). May be None with lines
            or points.
        normals: (N, 3) per-vertex normals; None gives each triangle its flat normal.
        uv: (N, 2) texture coordinates (u right, v down, as glTF); needed with a texture.
        colors: (N, 3) or (N, 4) linear RGB(A) vertex colours; None: white.
        texture: (H, W, 4) or (H, W, 3) uint8 base colour texture, row 0 the top row.
        lines: (S, 2) vertex indices of line segments; points: (P,) vertex indices of points.
        base_color: linear RGBA factor; double_sided: never culled; texture_srgb: the texture holds
            sRGB colour (glTF base colour textures do).
        """

        def ints(a: Optional[np.ndarray], what: str) -> Optional[np.ndarray]:
            if a is None:
                return None
            try:
                a = np.asarray(a)
            except (ValueError, TypeError) as error:
                raise Error(f"from_arrays: {what} must be an array of integers ({error})") from None
            if a.size and a.dtype.kind not in "iu":
                raise Error(f"from_arrays: {what} must be integers, not {a.dtype} ({_shown(a)})")
            if a.dtype != np.uint32:
                # Negative indices and those past 32 bits are out of range, as in the loaders (dropped
                # with a warning), never wrapped onto a valid vertex. In int64, so that numpy 2's
                # promotion rules keep EMPTY_ID representable whatever the input's integer type.
                wide = a.astype(np.int64)
                a = np.where((wide < 0) | (wide > EMPTY_ID), np.int64(EMPTY_ID), wide).astype(np.uint32)
            return a

        what = "from_arrays"
        positions, indices, normals, uv, colors, texture, lines, points = (
            _host_copy(a, what) for a in (positions, indices, normals, uv, colors, texture, lines, points))
        positions = _real_array(positions, "from_arrays: positions")
        tri = ints(indices, "indices")
        if tri is None:
            tri = np.zeros((0, 3), np.uint32)
        # Attributes must be finite: a NaN colour or normal has no shade to give (positions may not be:
        # their primitives are dropped with a warning, as the loaders drop them).
        if normals is not None:
            normals = _real_array(normals, "from_arrays: normals")
            _finite(normals, "from_arrays: normals")
        if uv is not None:
            uv = _real_array(uv, "from_arrays: uv")
            _finite(uv, "from_arrays: uv")
        if colors is not None:
            colors = _real_array(colors, "from_arrays: colors")
            _finite(colors, "from_arrays: colors")
            if colors.ndim == 2 and colors.shape[1] == 3:
                colors = np.concatenate([colors, np.ones((colors.shape[0], 1), np.float32)], axis=1)
        if texture is not None:
            texture = np.asarray(texture)
            if texture.dtype != np.uint8:
                raise Error(f"from_arrays: texture must be uint8, not {texture.dtype}")
            if texture.ndim == 3 and texture.shape[2] == 3:
                alpha = np.full(texture.shape[:2] + (1,), 255, np.uint8)
                texture = np.concatenate([texture, alpha], axis=2)
        base = _real_array(base_color, "from_arrays: base_color", np.float64)
        if base.shape != (4,):
            raise Error(f"from_arrays: base_color must be four numbers (linear RGBA), not {_shown(base_color)}")
        for name, flag in (("double_sided", double_sided), ("texture_srgb", texture_srgb)):
            if not isinstance(flag, (bool, np.bool_)):
                raise Error(f"from_arrays: {name} must be True or False, not {_shown(flag)}")
        native = _raster.Scene.from_arrays(
            positions, tri, normals, uv, colors, texture, bool(texture_srgb), ints(lines, "lines"),
            ints(points, "points"), tuple(float(c) for c in base), bool(double_sided))
        _warn(native.warnings)
        return Scene(native)

    def update_positions(self, positions: np.ndarray) -> None:
        """Moves the vertices of a scene made by from_arrays, in place: `positions` has the shape the
        scene was made with ((N, 3) or (N, 4)); every primitive keeps its vertices, flat normals follow.
        A Renderer that drew this Scene uploads the positions alone before its next frame (no rebuild).
        Non-finite positions raise raster.Error and leave the scene as it was. A GPU array is copied to
        the host once (the Scene lives there; see from_arrays)."""
        positions = _real_array(_host_copy(positions, "update_positions: positions"), "update_positions: positions")
        self._native.update_positions(positions)

    @property
    def vertex_count(self) -> int:
        """Vertices after loading (flat-shaded meshes have three per triangle)."""
        return self._native.vertex_count

    @property
    def triangle_count(self) -> int:
        """Triangles; their ids are 0..triangle_count-1 in scene order."""
        return self._native.triangle_count

    @property
    def line_count(self) -> int:
        """Line segments; their ids follow the triangles'."""
        return self._native.line_count

    @property
    def point_count(self) -> int:
        """Points; their ids follow the segments'."""
        return self._native.point_count

    @property
    def bounds(self) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]:
        """(min, max) corners of the world-space bounding box of everything drawn."""
        return tuple(self._native.bounds_min), tuple(self._native.bounds_max)

    def __repr__(self) -> str:
        return (f"raster.Scene({self.triangle_count} triangles, {self.line_count} lines, "
                f"{self.point_count} points)")


class Frame:
    """One rendered frame. Every array is a numpy view of the buffers the library downloaded (no
    copy: its ``.base`` is the native frame); row 0 is the image's top row, pixel (x, y) is at
    ``[y, x]``.

    color: (H, W, 4) uint8 sRGB RGBA, every sample resolved in linear space (None unless asked for in
        Renderer.render's outputs; a DeviceArray of GPU memory with on_device=True, as ids and depth).
    ids: (H, W) uint32 id of the primitive at the pixel's AOV sample: triangles in scene order, then
        lines, then points; EMPTY_ID (0xFFFFFFFF) where empty.
    depth: (H, W) float32 window depth 0..1 of that sample (Vulkan: 0 at the near plane), 1 where empty.
    bary, uv, normal: (H, W, 2), (H, W, 2), (H, W, 3) float32 at pixel centres, or None unless
        rendered with surface_aovs=True: perspective-correct barycentric weights of the triangle's
        second and third vertex (the first's is 1 - sum), base colour texture coordinates, unit
        view-space shading normal; 0 where empty.
    ao: (H, W) float32 ambient occlusion the shading used (1 = open) when rendered with ao="gtao" or
        "reference", else None.
    sample_ids, sample_depth: (S, H*ssaa, W*ssaa) every sample's id and depth with aov_samples=True
        (S = msaa), else None.
    stats: the statistics ``raster render --stats`` writes (counts, stage times, settings) as a dict.
    warnings: what the render drew otherwise than asked, one line each (also issued as RasterWarning).
    gpu_ms: GPU time of the frame (median over ``repeat`` timed runs).
    device: the DeviceInfo that rendered it.
    """

    def __init__(self, native: Any) -> None:
        self._native = native
        self.width: int = native.width
        self.height: int = native.height
        self.gpu_ms: float = native.gpu_ms
        self.warnings: List[str] = list(native.warnings)

    @functools.cached_property
    def color(self) -> np.ndarray:
        return self._native.color

    @functools.cached_property
    def ids(self) -> np.ndarray:
        return self._native.ids

    @functools.cached_property
    def depth(self) -> np.ndarray:
        return self._native.depth

    @functools.cached_property
    def bary(self) -> Optional[np.ndarray]:
        return self._native.bary

    @functools.cached_property
    def uv(self) -> Optional[np.ndarray]:
        return self._native.uv

    @functools.cached_property
    def normal(self) -> Optional[np.ndarray]:
        return self._native.normal

    @functools.cached_property
    def ao(self) -> Optional[np.ndarray]:
        return self._native.ao

    @functools.cached_property
    def sample_ids(self) -> Optional[np.ndarray]:
        return self._native.sample_ids

    @functools.cached_property
    def sample_depth(self) -> Optional[np.ndarray]:
        return self._native.sample_depth

    @functools.cached_property
    def stats(self) -> Dict[str, Any]:
        return json.loads(self._native.stats_json)

    @functools.cached_property
    def device(self) -> DeviceInfo:
        return _device(self._native.device)

    def save(self, path: Union[str, "os.PathLike[str]"], *, png_compression: Optional[str] = None,
             exr_compression: Optional[str] = None) -> None:
        """Writes the file ``raster render`` writes for the path's extension, byte for byte: .png the
        colour (its -o), .exr the AOVs (its --aov: ids and depth, the surface AOVs, ao and every sample
        where the frame holds them, and the linear colour), .json the statistics (its --stats). The file
        appears whole or not at all. png_compression: "fast", "default" or "small" (the pixels are the
        same); exr_compression: "none", "rle", "zips", "zip" or "piz" (all lossless). raster.Error for
        another extension, a frame without the images the file holds, or a file that cannot be written.
        """
        self._native.save(os.fspath(path), png_compression=png_compression or "",
                          exr_compression=exr_compression or "")

    def __repr__(self) -> str:
        return f"raster.Frame({self.width}x{self.height}, {self.device.backend}, {self.gpu_ms:.3f} ms)"


Camera = Union[str, Tuple[np.ndarray, np.ndarray]]


class Renderer:
    """A session on one device: it keeps the device, the frame buffers and a session for each of the
    last few scenes rendered, so rendering the same Scene again uploads nothing, unless another scene
    was drawn in between: the device's buffers hold one scene at a time, and each frame shows its own
    scene (a switch uploads it again).

    backend: "auto" (CUDA when a CUDA GPU is present, else Vulkan), "cuda", "vulkan" or
    "vulkan-graphics" (the reference: the same scene through the Vulkan graphics pipeline).
    device: the device's index within its backend (see raster.devices()).

    render() releases the GIL while the device works; one Renderer renders one frame at a time
    (calls from several threads wait for each other), separate Renderers run side by side.
    """

    def __init__(self, backend: str = "auto", device: int = 0) -> None:
        self._native = _raster.Renderer(backend, int(device))
        self.device: DeviceInfo = _device(self._native.device)

    def render(self, scene: Scene, width: int, height: int, camera: Camera = "auto", *,
               surface_aovs: bool = False, outputs: Sequence[str] = OUTPUTS, on_device: bool = False,
               **settings: Any) -> Frame:
        """Renders `scene` at width x height and returns the Frame.

        camera: a spec string as ``raster render --camera`` takes ("auto": framed from the bounds, or
        the file's first camera; "gltf:N"; "orbit:AZ,EL,DIST[,TX,TY,TZ]" in degrees and scene units),
        or a (view, projection) pair of 4x4 numpy matrices in Vulkan's clip conventions (row-major as
        numpy prints them; depth 0..1 with the near plane at 0; NDC y = -1 the top row; a projection
        whose last row is (0, 0, -1, 0) is perspective, any other orthographic).
        surface_aovs: also compute Frame.bary, uv and normal (on the device).
        outputs: which of "color", "ids" and "depth" the frame holds (the others are None): only
            those are unpacked on the device and copied back, so a frame of ids alone moves a third of
            the bytes.
        on_device: leave the images in GPU memory (CUDA devices): Frame.color, ids and depth are then
            raster.DeviceArray objects that torch.from_dlpack, cupy.asarray and jax.dlpack take without
            a copy (DLPack, __cuda_array_interface__), whole when render returns.
        settings: any render setting of the schema by its key (raster.SETTINGS; the list below), with
        the schema's checks and one-line errors (raster.Error). Defaults are the schema's, except
        warmup = 0 (a session's earlier frames warm it up).
        """
        if not isinstance(scene, Scene):
            raise Error(f"render: scene must be a raster.Scene, not {_shown(scene)}")
        for name, flag in (("surface_aovs", surface_aovs), ("on_device", on_device)):
            if not isinstance(flag, (bool, np.bool_)):
                raise Error(f"render: {name} must be True or False, not {_shown(flag)}")
        _check_setting_keys("render", settings)
        args = dict(_SESSION_DEFAULTS)
        args.update(settings)
        args["width"], args["height"] = width, height
        native = self._native.render(scene._native, camera, _setting_values(args), bool(surface_aovs), True,
                                     _output_bits(outputs), bool(on_device))
        frame = Frame(native)
        _warn(frame.warnings)
        return frame

    def render_many(self, scene: Scene, width: int, height: int, cameras: Sequence[Camera], *,
                    outputs: Sequence[str] = OUTPUTS, on_device: bool = False,
                    **settings: Any) -> Dict[str, Any]:
        """Renders `scene` from every camera of `cameras` (spec strings or (view, projection) pairs, as
        render takes them) with one set of settings, and returns {"color": (N, H, W, 4) uint8,
        "ids": (N, H, W) uint32, "depth": (N, H, W) float32}, the images of `outputs` alone: frame k of
        them equals render(scene, width, height, cameras[k], ...)'s images byte for byte. On CUDA the
        frames are queued at once over several streams (one frame's images are copied out while the next
        is drawn) and the call waits once; with on_device=True the arrays stay in GPU memory
        (DeviceArrays). Triangles alone: lines and points modes, the wireframe, tessellation, level of
        detail, reference AO and the surface AOVs take render, one frame at a time.
        """
        if not isinstance(scene, Scene):
            raise Error(f"render_many: scene must be a raster.Scene, not {_shown(scene)}")
        if not isinstance(on_device, (bool, np.bool_)):
            raise Error(f"render_many: on_device must be True or False, not {_shown(on_device)}")
        if isinstance(cameras, (str, bytes)) or not isinstance(cameras, Sequence):
            raise Error(f"render_many: cameras must be a sequence of cameras, not {_shown(cameras)}")
        _check_setting_keys("render_many", settings)
        args = dict(_SESSION_DEFAULTS)
        args.update(settings)
        args["width"], args["height"] = width, height
        color, ids, depth, lines = self._native.render_many(scene._native, list(cameras), _setting_values(args),
                                                            _output_bits(outputs), bool(on_device))
        _warn(lines)
        return {name: array for name, array in (("color", color), ("ids", ids), ("depth", depth))
                if array is not None}

    def release(self) -> None:
        """Frees every scene upload and buffer this renderer keeps (the device stays open)."""
        self._native.release()

    def __repr__(self) -> str:
        return f"raster.Renderer({self.device.backend!r}, {self.device.index}: {self.device.name})"


def _output_bits(outputs: Any) -> int:
    """Renderer.render's outputs as the library's Output bits, or raster.Error naming what is wrong."""
    if isinstance(outputs, str) or not isinstance(outputs, (list, tuple, set, frozenset)):
        raise Error(f"render: outputs must be a sequence of names out of {', '.join(OUTPUTS)}, not "
                    f"{_shown(outputs)}")
    bits = 0
    for name in outputs:
        if name not in _OUTPUT_BITS:
            raise Error(f"render: unknown output {_shown(name)} (expected {', '.join(OUTPUTS)})")
        bits |= _OUTPUT_BITS[name]
    return bits


def _check_setting_keys(what: str, settings: Dict[str, Any]) -> None:
    """raster.Error for a keyword that is not a setting of the schema, naming the nearest one."""
    keys = [s["key"] for s in SETTINGS if s["key"] not in _PARAMETERS]
    for key in settings:
        if key in keys:
            continue
        if key in _PARAMETERS:
            raise Error(f"{what}: {key} is a parameter of its own (scene, width, height, camera), not a "
                        f"keyword setting")
        # Quoted as the library quotes input: the first 100 characters and the length of the rest.
        shown = repr(key) if len(key) <= 100 else f"'{key[:100]}'... ({len(key.encode())} bytes)"
        near = [k for k in keys if k.lower() == key.lower()]
        if not near and len(key) <= 64:
            near = difflib.get_close_matches(key, keys, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else " (raster.SETTINGS lists them)"
        raise Error(f"{what}: unknown setting {shown}{hint}")


def _setting_values(args: Dict[str, Any]) -> Dict[str, Any]:
    """Keyword settings as the native module takes them: numpy scalars and 0-d arrays as the Python
    number, bool or string they hold (np.int64(4) is 4), anything else as given (the schema checks it)."""
    out = {}
    for key, value in args.items():
        if isinstance(value, np.ndarray) and value.ndim == 0:
            value = value.item()
        elif isinstance(value, np.generic):
            value = value.item()
        out[key] = value
    return out


def _default(setting: Dict[str, Any]) -> Any:
    """Renderer.render's default of a setting, floats as the float32 the schema stores, printed short."""
    value = _SESSION_DEFAULTS.get(setting["key"], setting["default"])
    if isinstance(value, float):
        return float(f"{value:.7g}")
    if isinstance(value, list):
        return tuple(float(f"{v:.7g}") for v in value)
    return value


def _settings_doc() -> str:
    lines = ["", "        Settings (keyword, type, default: meaning):", ""]
    for s in SETTINGS:
        if s["key"] in _PARAMETERS:
            continue
        kind = s["type"]
        if "choices" in s:
            kind = " | ".join(s["choices"])
        default = _default(s)
        lines.append(f"        {s['key']} ({kind}, {default!r}): {s['help']}")
    return "\n".join(lines) + "\n"


Renderer.render.__doc__ += _settings_doc()

_shared: Dict[str, Renderer] = {}
_shared_lock = threading.Lock()


def _shared_renderer(backend: str) -> Renderer:
    """One Renderer per backend for the module-level functions (rasterize), opened on first use."""
    with _shared_lock:
        if backend not in _shared:
            _shared[backend] = Renderer(backend)
        return _shared[backend]


# rasterize's camera: positions are already in clip space (identity view), and OpenGL's clip depth
# -w..w (nvdiffrast's) becomes Vulkan's 0..w, z' = (z + w) / 2, so the pipeline clips where OpenGL does.
_IDENTITY = np.eye(4, dtype=np.float32)
_GL_TO_VULKAN_DEPTH = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0.5, 0.5], [0, 0, 0, 1]], np.float32)


def _resolution(resolution: Any) -> Tuple[int, int]:
    """(height, width) as two integers within the settings' range, or raster.Error with the value given."""
    limit = {s["key"]: int(s["max"]) for s in SETTINGS if s["key"] in ("width", "height")}
    try:
        height, width = resolution
    except (TypeError, ValueError):
        raise Error(f"resolution must be (height, width), not {_shown(resolution)}") from None
    for name, v in (("height", height), ("width", width)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Integral) or not 1 <= v <= limit[name]:
            raise Error(f"resolution {_shown(resolution)}: the {name} must be an integer in "
                        f"1..{limit[name]}, not {_shown(v)}")
    return int(height), int(width)


def _triangles(tri: Any, vertices: int, what: str, vertices_text: str) -> np.ndarray:
    """`tri` as an integer (T, 3) array naming vertices below `vertices`, or raster.Error (`vertices_text`
    says what the vertices are, after the index named)."""
    tri = np.asarray(_host_copy(tri, f"{what}: tri"))
    if tri.ndim != 2 or tri.shape[1] != 3 or (tri.size and tri.dtype.kind not in "iu"):
        raise Error(f"{what}: tri must be integer (T, 3), not {tri.dtype} {tuple(tri.shape)}")
    if tri.size and (tri.min() < 0 or tri.max() >= vertices):
        raise Error(f"{what}: tri indexes vertex {int(tri.min() if tri.min() < 0 else tri.max())}{vertices_text}")
    return tri


def _detached(value: Any) -> Any:
    """A tensor that records gradients, without them (torch exports neither numpy, DLPack nor the CUDA
    array interface of one); anything else as it is."""
    if getattr(value, "requires_grad", False) and callable(getattr(value, "detach", None)):
        return value.detach()
    return value


@dataclass
class _GpuArray:
    """An array in CUDA memory, from its __cuda_array_interface__ (version 2 or 3)."""
    pointer: int
    shape: Tuple[int, ...]
    typestr: str
    stream: int  # the interface's stream: 0 none to wait for, 1 legacy default, 2 per-thread, else a handle
    owner: Any   # the object, alive while the pointer is used


def _gpu_array(value: Any, what: str) -> Optional[_GpuArray]:
    """`value`'s CUDA memory when it is a GPU array (torch, CuPy, JAX, Numba: anything with the CUDA array
    interface), C-contiguous; None for anything else."""
    value = _detached(value)
    try:
        face = value.__cuda_array_interface__
    except AttributeError:
        return None
    except Exception as error:  # the producer refuses to export (e.g. a tensor of another kind)
        raise Error(f"{what}: its CUDA array interface is not available ({error})") from None
    shape = tuple(int(n) for n in face["shape"])
    typestr = str(face["typestr"])
    item = int(typestr[2:]) if typestr[2:].isdigit() else 0
    strides = face.get("strides")
    if strides is not None:
        expected, step = [], item
        for n in reversed(shape):
            expected.insert(0, step)
            step *= n
        if any(n > 1 and int(s) != e for n, s, e in zip(shape, strides, expected)):
            raise Error(f"{what} must be contiguous on the GPU (call .contiguous()), not strided {tuple(strides)}")
    if face.get("mask") is not None:
        raise Error(f"{what}: masked GPU arrays are not taken")
    stream = face.get("stream")
    return _GpuArray(int(face["data"][0]), shape, typestr, 0 if stream is None else int(stream), value)


def _host_copy(value: Any, what: str) -> Any:
    """A GPU array's contents in host memory (through the producer's own copy: torch's .cpu(), CuPy's
    .get()); anything else as it is."""
    value = _detached(value)
    if not hasattr(value, "__cuda_array_interface__"):
        return value
    for method in ("cpu", "get"):
        copy = getattr(value, method, None)
        if callable(copy):
            return np.asarray(copy())
    raise Error(f"{what}: a GPU array of {type(value).__name__} has no copy to the host (.cpu() or .get())")


def _returned_like(result: Any, given: Any, on_gpu: bool) -> Any:
    """`result` (numpy, or a DeviceArray) in the kind of array the caller gave: a torch tensor for a torch
    tensor, a CuPy array for a CuPy array (both without a copy, through DLPack) where the result is where
    that library keeps its arrays (on_gpu: `given` is on the GPU); numpy and DeviceArray otherwise."""
    module = type(given).__module__.partition(".")[0]
    if module in ("numpy", "builtins", "raster"):
        return result
    library = __import__("sys").modules.get(module)
    convert = getattr(library, "from_dlpack", None)
    if convert is None or on_gpu != isinstance(result, DeviceArray):
        return result
    if module == "torch" and isinstance(result, DeviceArray):
        # The images are whole already: torch gets the DLPack capsule itself, without the protocol's
        # query of its current stream to synchronise with (a third of the call's host time at 1080p).
        return convert(result.__dlpack__())
    return convert(result)


def rasterize(pos: Any, tri: Any, resolution: Tuple[int, int], backend: str = "auto",
              msaa: int = 1, *, renderer: Optional["Renderer"] = None,
              on_device: Optional[bool] = None) -> Any:
    """The forward pass of nvdiffrast's ``rasterize``, by this project's exact fixed-point rasterizer
    (1/256-pixel vertices, top-left rule: Vulkan's coverage rules on every backend).

    pos: clip-space positions, float32 (V, 4) or (B, V, 4) (x, y, z, w) with OpenGL's depth range
        (-w <= z <= w is inside), as nvdiffrast takes them: a host array (numpy, a CPU tensor) or an
        array already on the GPU (a torch or CuPy tensor: anything with ``__cuda_array_interface__``),
        read there without a copy to the host, after the work queued on the stream it names.
    tri: int32 (T, 3) vertex indices (shared by every batch element); no face is culled. On the GPU it is
        copied to the host when it changes (a torch tensor's version counter says when; other GPU arrays
        every call), since each topology is kept as a scene.
    resolution: (height, width).
    backend: "auto", "cuda" or "vulkan"; msaa: 1, 2, 4, 8 or 16 samples per pixel (the output then
        describes each pixel's first sample).
    renderer: draw with this Renderer (its device; backend is then ignored) instead of the module's
        own one per backend, opened on first use. Either keeps one scene per topology: the B views are
        drawn from their positions alone, on CUDA all in one submission, and (u, v, z/w, id + 1) are
        computed on the device and copied straight into the returned array.
    on_device: return the output in GPU memory (CUDA devices); None (the default): where pos is.

    Returns float32 (B, H, W, 4) = (u, v, z/w, triangle_id + 1), all 0 where no triangle covers the
    pixel centre: u and v are the perspective-correct weights of the triangle's first and second
    vertex (the third's is 1 - u - v), z/w the clip-space depth in OpenGL's -1..1. Row 0 is at NDC
    y = -1, pixel (x, y) centred at NDC ((x + 0.5) / W * 2 - 1, (y + 0.5) / H * 2 - 1): nvdiffrast's
    layout; this project's own frames use the same rows (Vulkan's y = -1 is the top row), so
    rasterize's output and a Frame line up without a flip. It comes back in the kind of array pos is:
    numpy for numpy; for a torch tensor a torch tensor (on the GPU when on the device), for CuPy a CuPy
    array, both sharing the output's memory; a raster.DeviceArray (DLPack and the CUDA array interface)
    otherwise. Unlike nvdiffrast it returns the array alone (no derivatives, no gradients).
    A triangle with a corner that is not finite raises raster.Error (checked on the device).
    """
    given = pos
    gpu = _gpu_array(pos, "rasterize: pos")
    given_on_gpu = gpu is not None
    if gpu is not None:
        shape = gpu.shape if len(gpu.shape) != 2 else (1,) + gpu.shape
        if len(shape) != 3 or shape[2] != 4:
            raise Error(f"rasterize: pos must have shape (V, 4) or (B, V, 4), not {gpu.shape}")
        if gpu.typestr != "<f4":
            raise Error(f"rasterize: pos on the GPU must be float32, not {gpu.typestr}")
        host_pos = None
        batch, vertices = shape[0], shape[1]
    else:
        host_pos = _real_array(_detached(pos), "rasterize: pos")
        if host_pos.ndim == 2:
            host_pos = host_pos[None]
        if host_pos.ndim != 3 or host_pos.shape[2] != 4:
            raise Error(f"rasterize: pos must have shape (V, 4) or (B, V, 4), not {tuple(host_pos.shape)}")
        batch, vertices = host_pos.shape[0], host_pos.shape[1]
    indices = _indices(tri, vertices)
    height, width = _resolution(resolution)
    if on_device is None:
        on_device = gpu is not None
    if not isinstance(on_device, (bool, np.bool_)):
        raise Error(f"rasterize: on_device must be True, False or None, not {_shown(on_device)}")
    if indices.shape[0] == 0 and not on_device:
        try:
            return _returned_like(np.zeros((batch, height, width, 4), np.float32), given, given_on_gpu)
        except MemoryError:
            raise Error(f"rasterize: the output, {batch} x {height} x {width} x 4 float32 "
                        f"({batch * height * width * 16 / 2**30:.1f} GiB), does not fit in memory") from None
    if renderer is None:
        renderer = _shared_renderer(backend)
    elif not isinstance(renderer, Renderer):
        raise Error(f"rasterize: renderer must be a raster.Renderer, not {_shown(renderer)}")
    settings = _setting_values({"cull": "none", "warmup": 0, "msaa": msaa, "shading": "id",
                                "width": width, "height": height})
    if indices.shape[0] == 0:
        # Nothing to draw: zeros, in GPU memory from an empty scene's frame (a point outside the view).
        host_pos, gpu = np.array([[[2, 2, 0, 1]] * 3] * batch, np.float32), None
        indices, vertices = np.zeros((1, 3), np.uint32), 3
    scene = _topology_scene(renderer, vertices, indices)
    device_pos = None if gpu is None else (gpu.pointer, gpu.stream)
    out, invalid, lines = renderer._native.rasterize(scene, host_pos, device_pos, (batch, height, width),
                                                     (_IDENTITY, _GL_TO_VULKAN_DEPTH), settings, bool(on_device))
    _warn(lines)
    for view, dropped in enumerate(invalid):
        if dropped:
            raise Error(f"rasterize: pos[{view}] has non-finite values: {dropped} triangle(s) with a corner "
                        f"that is NaN, infinite or too large")
    return _returned_like(out, given, given_on_gpu)


# rasterize's GPU triangles, copied to the host: per tensor (by id, with a weak reference that says it is
# still that tensor) its version counter, the copy and its largest index, so that an unchanged torch
# tensor is neither copied nor checked again. The last few tensors are kept.
_gpu_triangles: Dict[int, Tuple[Any, int, np.ndarray, int]] = {}


def _indices(tri: Any, vertices: int) -> np.ndarray:
    """rasterize's `tri` checked against `vertices`, as a C-contiguous uint32 array on the host."""
    tri = _detached(tri)
    known = _gpu_triangles.get(id(tri))
    if known is not None and known[0]() is tri and known[1] == getattr(tri, "_version", None) and known[3] < vertices:
        return known[2]
    version = getattr(tri, "_version", None) if hasattr(tri, "__cuda_array_interface__") else None
    checked = np.ascontiguousarray(_triangles(tri, vertices, "rasterize", f" of {vertices}"), dtype=np.uint32)
    if version is not None:
        try:
            alive = weakref.ref(tri)
        except TypeError:  # not weakly referenceable: copied every call
            return checked
        if len(_gpu_triangles) >= 8:
            _gpu_triangles.clear()
        _gpu_triangles[id(tri)] = (alive, version, checked, int(checked.max()) if checked.size else -1)
    return checked


# rasterize's scenes: per Renderer, the last topology drawn (its triangles and vertex count) and the
# scene made for it, which every call draws with its own positions (Session.renderViews).
_topologies: "weakref.WeakKeyDictionary[Renderer, Tuple[np.ndarray, int, Any]]" = weakref.WeakKeyDictionary()


def _topology_scene(renderer: Renderer, vertices: int, indices: np.ndarray) -> Any:
    """The native scene of `indices` over `vertices` vertices for `renderer`."""
    with _shared_lock:
        known = _topologies.get(renderer)
        if known is not None and known[1] == vertices and (known[0] is indices or np.array_equal(known[0], indices)):
            # The caller's array from now on, so that the next call with it is known by identity.
            _topologies[renderer] = (indices, vertices, known[2])
            return known[2]
        # Made at the origin, where no triangle is dropped (every call draws its own positions), with
        # normals, so that the vertices are the arrays' own (rasterize shades ids: zeros do).
        zeros = np.zeros((vertices, 4), np.float32)
        scene = _raster.Scene.from_arrays(zeros, indices, np.zeros((vertices, 3), np.float32), None, None,
                                          None, True, None, None, (1.0, 1.0, 1.0, 1.0), False)
        _topologies[renderer] = (indices, vertices, scene)
        return scene


def interpolate(attr: Any, rast: Any, tri: Any, *, renderer: Optional["Renderer"] = None) -> Any:
    """nvdiffrast's ``interpolate`` (forward): per-vertex attributes at every pixel of ``rast``.

    attr: float32 (V, C) or (B, V, C); rast: (B, H, W, 4) from rasterize; tri: int32 (T, 3). All three on
        the host (numpy, CPU tensors), or all three on a CUDA GPU (torch, CuPy: anything with
        ``__cuda_array_interface__``, contiguous), where a kernel interpolates in place, after the work
        queued on their stream, on `renderer`'s device (or the module's CUDA Renderer).
    Returns float32 (B, H, W, C) = u * a0 + v * a1 + (1 - u - v) * a2 of the pixel's triangle, 0 where
    empty, each product and sum rounded on its own: the same bits on the host and on the GPU. It comes
    back in attr's kind of array (torch in, torch out; numpy in, numpy out; a DeviceArray otherwise).
    Unlike nvdiffrast it returns the array alone (no derivatives).
    """
    given = attr
    gpu = [_gpu_array(attr, "interpolate: attr"), _gpu_array(rast, "interpolate: rast"),
           _gpu_array(tri, "interpolate: tri")]
    if any(g is not None for g in gpu):
        return _interpolate_on_gpu(gpu, given, renderer)
    attr = _real_array(_detached(attr), "interpolate: attr")
    rast = _real_array(_detached(rast), "interpolate: rast")
    if rast.ndim != 4 or rast.shape[3] != 4:
        raise Error(f"interpolate: rast must have shape (B, H, W, 4), not {tuple(rast.shape)}")
    if attr.ndim not in (2, 3) or (attr.ndim == 3 and attr.shape[0] != rast.shape[0]):
        raise Error(f"interpolate: attr must have shape (V, C) or (B, V, C) with B = {rast.shape[0]}, "
                    f"not {tuple(attr.shape)}")
    vertices = attr.shape[-2]
    tri = _triangles(tri, vertices, "interpolate", f", but attr has {vertices} rows")
    out = np.empty(rast.shape[:3] + (attr.shape[-1],), np.float32)
    bad, _ = _raster.interpolate(attr if attr.ndim == 3 else attr[None], rast,
                                 np.ascontiguousarray(tri, dtype=np.uint32), out)
    if bad >= 0:
        slot = float(rast[..., 3].flat[bad])
        raise Error(f"interpolate: rast[..., 3] holds {_shown(slot)}, not a triangle id + 1 of the "
                    f"{tri.shape[0]} triangles in tri (or 0)")
    return _returned_like(out, given, False)


def _interpolate_on_gpu(gpu: List[Optional[_GpuArray]], given: Any, renderer: Optional["Renderer"]) -> Any:
    """interpolate of three GPU arrays (attr, rast, tri), on the device."""
    if any(g is None for g in gpu):
        where = ", ".join(f"{name} {'on the GPU' if g is not None else 'on the host'}"
                          for name, g in zip(("attr", "rast", "tri"), gpu))
        raise Error(f"interpolate: attr, rast and tri must be all on the host or all on the GPU, not {where}")
    attr, rast, tri = gpu
    if len(rast.shape) != 4 or rast.shape[3] != 4 or rast.typestr != "<f4":
        raise Error(f"interpolate: rast must be float32 (B, H, W, 4), not {rast.typestr} {rast.shape}")
    attr_shape = (1,) + attr.shape if len(attr.shape) == 2 else attr.shape
    if len(attr_shape) != 3 or attr_shape[0] not in (1, rast.shape[0]) or attr.typestr != "<f4":
        raise Error(f"interpolate: attr must be float32 (V, C) or (B, V, C) with B = {rast.shape[0]}, "
                    f"not {attr.typestr} {attr.shape}")
    if len(tri.shape) != 2 or tri.shape[1] != 3 or tri.typestr not in ("<i4", "<u4"):
        raise Error(f"interpolate: tri must be int32 (T, 3), not {tri.typestr} {tri.shape}")
    if renderer is None:
        renderer = _shared_renderer("cuda")
    elif not isinstance(renderer, Renderer):
        raise Error(f"interpolate: renderer must be a raster.Renderer, not {_shown(renderer)}")
    stream = next((g.stream for g in gpu if g.stream), 0)
    out, bad_pixel, bad_triangle = renderer._native.interpolate_on_device(
        attr.pointer, attr_shape, rast.pointer, rast.shape, tri.pointer, tri.shape[0], stream)
    if bad_triangle >= 0:
        raise Error(f"interpolate: tri[{bad_triangle}] indexes a vertex beyond attr's {attr_shape[1]} rows")
    if bad_pixel >= 0:
        raise Error(f"interpolate: rast[..., 3] of pixel {bad_pixel} (flat) is not a triangle id + 1 of the "
                    f"{tri.shape[0]} triangles in tri (or 0)")
    return _returned_like(out, given, True)


def compare(a: Union[Frame, str, os.PathLike], b: Union[Frame, str, os.PathLike], *, what: str = "both",
            tolerance: int = 0, max_id_mismatches: int = 0, depth_tolerance: float = 0.0,
            surface_tolerance: Optional[float] = None) -> Dict[str, Any]:
    """``raster compare``'s metrics as a dict.

    a, b: two Frames of one size, or two files of one kind (.png colour, .exr AOVs) as
    ``raster compare A B`` takes them. what (frames only): "color", "aov" (ids, depth, the surface
    AOVs and every sample when both frames have them) or "both".
    tolerance: largest allowed 8-bit colour difference; max_id_mismatches: pixels (samples) whose id or
    coverage may differ; depth_tolerance: largest allowed depth difference; surface_tolerance: largest
    allowed bary/uv/normal difference (None: reported, not checked).

    Returns "passed", "text" (the report the command prints, ending in PASS or FAILURE), "kind",
    "width", "height" and the metrics: colour "mean_error", "rms_error", "psnr", "max_error",
    "max_error_at" (x, y), "pixels_over_tolerance"; AOV "id_mismatches", "coverage_mismatches",
    "max_depth_diff", "mean_depth_diff", "max_bary_diff", "max_uv_diff", "max_normal_diff",
    "surface_over_tolerance", "samples_per_pixel", "sample_id_mismatches",
    "sample_depth_over_tolerance". With what="both" the keys of both, "kind" = "both", "passed" when
    both pass and "text" both reports.
    """
    options = (int(tolerance), int(max_id_mismatches), float(depth_tolerance), surface_tolerance)
    if isinstance(a, Frame) and isinstance(b, Frame):
        if what not in ("color", "aov", "both"):
            raise Error(f"compare: what must be color, aov or both, not {what!r}")
        kinds = ["color", "aov"] if what == "both" else [what]
        reports = [_raster.compare(a._native, b._native, kind == "aov", *options) for kind in kinds]
        if len(reports) == 1:
            return reports[0]
        merged = dict(reports[0])
        merged.update(reports[1])
        merged["kind"] = "both"
        merged["passed"] = all(r["passed"] for r in reports)
        merged["text"] = "".join(r["text"] for r in reports)
        return merged
    if isinstance(a, Frame) or isinstance(b, Frame):
        raise Error("compare: give two Frames or two file names")
    return _raster.compare_files(os.fspath(a), os.fspath(b), *options)


def __dir__() -> List[str]:
    """The module's API (__all__), not the names it imports to implement it."""
    return sorted(__all__)
