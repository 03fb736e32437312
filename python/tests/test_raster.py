"""The Python module against independent expectations: the `raster` command's images and messages,
analytic coverage and barycentrics, an OBJ file of the same mesh, the settings schema."""

import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import raster
import raster.testing
from conftest import SOURCE_DIR, read_png, renderer, run_cli

W, H = 48, 32


# ---- devices, frames -------------------------------------------------------------------------------

def test_devices_open_as_listed(vulkan):
    listed = raster.devices()
    vulkan_devices = [d for d in listed if d.backend == "vulkan"]
    assert vulkan_devices, listed
    assert [d.index for d in vulkan_devices] == list(range(len(vulkan_devices)))
    for d in listed:
        assert d.kind == ("cpu" if d.cpu else "gpu")
        assert raster.Renderer(d.backend, d.index).device.name == d.name
    if not any(d.backend == "cuda" for d in listed) and not raster.testing.missing_backend_allowed("cuda"):
        pytest.fail("no CUDA device listed and SR_ALLOW_MISSING_BACKENDS does not allow it")


def test_frame_arrays_shapes_dtypes_and_rows_match_the_cli_png(vulkan, tmp_path):
    frame = vulkan.render(raster.Scene.load("builtin"), W, H, "orbit:30,20,4", surface_aovs=True)
    assert (frame.width, frame.height) == (W, H)
    assert frame.color.shape == (H, W, 4) and frame.color.dtype == np.uint8
    assert frame.ids.shape == (H, W) and frame.ids.dtype == np.uint32
    assert frame.depth.shape == (H, W) and frame.depth.dtype == np.float32
    assert frame.bary.shape == (H, W, 2) and frame.bary.dtype == np.float32
    assert frame.uv.shape == (H, W, 2) and frame.normal.shape == (H, W, 3)
    assert frame.sample_ids is None and frame.sample_depth is None
    # Row 0 is the top row of the PNG the command line writes for the same render (at the library's one
    # sample per pixel: `raster render` alone would anti-alias).
    png = tmp_path / "cli.png"
    run_cli("render", "builtin", "--backend", "vulkan", "--width", W, "--height", H, "--camera", "orbit:30,20,4",
            "--msaa", 1, "--warmup", 0, "-q", "-o", png)
    np.testing.assert_array_equal(frame.color, read_png(png))
    empty = frame.ids == raster.EMPTY_ID
    assert empty.any() and (~empty).any()
    assert (frame.depth[empty] == 1.0).all() and (frame.depth[~empty] < 1.0).all()
    assert (frame.bary[empty] == 0).all()
    assert frame.stats["resolution"] == [W, H] and frame.stats["backend"] == "vulkan"


def test_camera_distance_in_bounding_radii_matches_the_cli(vulkan, tmp_path):
    # "2.5r": 2.5 radii of the scene's bounding sphere, resolved as `raster render --camera` resolves it.
    frame = vulkan.render(raster.Scene.load("builtin"), W, H, "orbit:30,20,2.5r", msaa=1)
    png = tmp_path / "cli.png"
    run_cli("render", "builtin", "--backend", "vulkan", "--width", W, "--height", H, "--camera", "orbit:30,20,2.5r",
            "--msaa", 1, "--warmup", 0, "-q", "-o", png)
    np.testing.assert_array_equal(frame.color, read_png(png))
    assert frame.stats["camera"]["spec"] == "orbit:30,20,2.5r"


def test_level_of_detail_is_a_keyword_and_matches_the_cli(vulkan, tmp_path):
    # lod="on" draws the cut the command line's --lod on draws (the same image), fewer triangles than the
    # sphere has, and the id array still names the scene's triangles.
    scene = raster.Scene.load("builtin:dense")
    frame = vulkan.render(scene, W, H, "orbit:20,25,2.5r", lod="on", lod_error_px=2.0)
    full = vulkan.render(scene, W, H, "orbit:20,25,2.5r")
    assert 0 < frame.stats["lod"]["triangles"] < frame.stats["lod"]["scene_triangles"]
    assert "lod" not in full.stats
    covered = frame.ids != raster.EMPTY_ID
    assert covered.sum() > 100 and (frame.ids[covered] < frame.stats["lod"]["scene_triangles"]).all()
    png = tmp_path / "cli.png"
    run_cli("render", "builtin:dense", "--backend", "vulkan", "--width", W, "--height", H, "--camera",
            "orbit:20,25,2.5r", "--lod", "on", "--lod-error-px", 2, "--msaa", 1, "--warmup", 0, "-q", "-o", png)
    np.testing.assert_array_equal(frame.color, read_png(png))


def test_ambient_occlusion_is_a_keyword_an_array_and_matches_the_cli(vulkan, tmp_path):
    # ao="gtao" fills frame.ao (float32, 1 = open), shading="ao" shows it, and the image is the one the
    # command line's --ao gtao draws; without AO there is no array.
    scene = raster.Scene.load("builtin")
    frame = vulkan.render(scene, W, H, "orbit:30,30,2.2r", ao="gtao", ao_slices=3, shading="ao")
    assert frame.ao.dtype == np.float32 and frame.ao.shape == (H, W)
    covered = frame.ids != raster.EMPTY_ID
    assert ((frame.ao >= 0) & (frame.ao <= 1)).all() and frame.ao[covered].min() < 0.9
    assert vulkan.render(scene, W, H, "orbit:30,30,2.2r").ao is None
    png = tmp_path / "cli.png"
    run_cli("render", "builtin", "--backend", "vulkan", "--width", W, "--height", H, "--camera",
            "orbit:30,30,2.2r", "--ao", "gtao", "--ao-slices", 3, "--shading", "ao", "--msaa", 1, "--warmup", 0,
            "-q", "-o", png)
    np.testing.assert_array_equal(frame.color, read_png(png))


def test_rows_from_the_top_with_explicit_matrices(vulkan):
    # A triangle in the upper half of NDC (y < 0 is up in Vulkan's clip space) covers only top rows.
    pos = np.array([[-0.5, -0.9, 0.5], [0.5, -0.9, 0.5], [0.0, -0.2, 0.5]], np.float32)
    scene = raster.Scene.from_arrays(pos, np.array([[0, 1, 2]]), double_sided=True)
    frame = vulkan.render(scene, 32, 32, (np.eye(4), np.eye(4)))
    rows = np.nonzero((frame.ids == 0).any(axis=1))[0]
    assert rows.min() == 2 and rows.max() < 16


def test_sample_aovs_are_every_sample(vulkan):
    frame = vulkan.render(raster.Scene.load("builtin"), W, H, msaa=4, ssaa=2, aov_samples=True)
    assert frame.sample_ids.shape == (4, 2 * H, 2 * W) and frame.sample_ids.dtype == np.uint32
    assert frame.sample_depth.shape == (4, 2 * H, 2 * W) and frame.sample_depth.dtype == np.float32
    # The pixel's AOV sample is sample 0 of the raster pixel (ssaa/2, ssaa/2) of its block.
    np.testing.assert_array_equal(frame.ids, frame.sample_ids[0, 1::2, 1::2])
    np.testing.assert_array_equal(frame.depth, frame.sample_depth[0, 1::2, 1::2])


def test_outputs_are_views_of_the_downloaded_buffers(vulkan):
    frame = vulkan.render(raster.Scene.load("builtin"), W, H, surface_aovs=True, msaa=2, aov_samples=True)
    for name in ("color", "ids", "depth", "bary", "uv", "normal", "sample_ids", "sample_depth"):
        array = getattr(frame, name)
        assert array.base is frame._native, name
        assert not array.flags.owndata, name
        assert getattr(frame, name) is array, name
        # Another view of the same buffer sees a write through this one: no copy in between.
        other = getattr(frame._native, name)
        assert other is not array and np.shares_memory(other, array), name
    frame.ids[0, 0] = 12345
    assert frame._native.ids[0, 0] == 12345


# ---- settings --------------------------------------------------------------------------------------

def other_value(setting):
    """A valid value of `setting` other than its default."""
    default, kind = setting["default"], setting["type"]
    if kind == "choice":
        return next(c for c in setting["choices"] if c != default)
    if kind == "bool":
        return not default
    if kind == "vec3":
        return [0.5, 0.25, 1.0]
    if kind == "uint":
        if "values" in setting:
            return next(v for v in setting["values"] if v != default)
        return 2 if default == "auto" else default + 1
    if kind == "float":
        return default + (setting.get("step") or 1.0)
    if kind == "model":
        return "translate:0.5,0,0,rotate:0,90,0,scale:1.5"
    raise AssertionError(f"a setting type the test does not know: {kind}")


def test_every_schema_setting_is_a_keyword(vulkan):
    scene = raster.Scene.load("builtin")
    keys = [s["key"] for s in raster.SETTINGS]
    assert set(keys) == {n.replace("-", "_") for n in raster._raster.settings_names()}
    assert {"msaa", "shading", "texture_filter", "raster_method", "primitive_mode", "tessellate"} <= set(keys)
    for setting in raster.SETTINGS:
        key = setting["key"]
        if key in ("width", "height", "camera"):
            continue
        value = other_value(setting)
        frame = vulkan.render(scene, 24, 16, **{key: value})
        echoed = frame.stats["settings"][key]
        if isinstance(value, (float, list)):
            np.testing.assert_allclose(echoed, value, rtol=1e-6, err_msg=key)
        else:
            assert echoed == value, key
    frame = vulkan.render(scene, 24, 16, "orbit:10,20,3")
    assert frame.stats["settings"]["camera"] == "orbit:10,20,3"
    assert (frame.stats["settings"]["width"], frame.stats["settings"]["height"]) == (24, 16)


def test_model_moves_the_scene_as_the_camera_moved_the_other_way(vulkan):
    # `model` is a setting like any other: a translation t draws what the orbit target moved by -t
    # draws (tests/model_transform_test.cpp has the analytic cases).
    scene = raster.Scene.load("builtin")
    moved = vulkan.render(scene, W, H, "orbit:30,20,6", model="translate:0.5,-0.25,0.75", msaa=1)
    camera = vulkan.render(scene, W, H, "orbit:30,20,6,-0.5,0.25,-0.75", msaa=1)
    still = vulkan.render(scene, W, H, "orbit:30,20,6", msaa=1)
    np.testing.assert_array_equal(moved.ids, camera.ids)
    assert (moved.ids != still.ids).any()
    assert moved.stats["settings"]["model"] == "translate:0.5,-0.25,0.75"
    # A quarter turn about y is the azimuth turned back 90 degrees (equal up to the rounding of two
    # orbit bases: an edge pixel at most).
    turned = vulkan.render(scene, W, H, "orbit:30,20,6", model="rotate:0,90,0", msaa=1)
    assert (turned.ids != vulkan.render(scene, W, H, "orbit:-60,20,6", msaa=1).ids).sum() <= 1
    with pytest.raises(raster.Error) as error:
        vulkan.render(scene, 8, 8, model="scale:0")
    assert str(error.value) == "invalid model 'scale:0': scale takes one number S above 0"


def test_render_docstring_and_stubs_list_every_setting():
    doc = raster.Renderer.render.__doc__
    stub = (SOURCE_DIR / "python" / "raster" / "__init__.pyi").read_text()
    for s in raster.SETTINGS:
        if s["key"] not in ("width", "height", "camera"):
            assert f"        {s['key']} (" in doc, s["key"]
            assert f"        {s['key']}: " in stub, s["key"]
    check = subprocess.run([sys.executable, str(SOURCE_DIR / "python" / "gen_stubs.py"), "--check"],
                           capture_output=True, text=True)
    assert check.returncode == 0, check.stderr


# ---- errors ----------------------------------------------------------------------------------------

def cli_error(*args):
    code, _, err = run_cli(*args, check=False)
    assert code == 2
    return err.strip().splitlines()[-1]


def test_errors_carry_the_cli_message(vulkan, tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(raster.Error) as error:
        raster.Scene.load(missing)
    assert "raster: error: " + str(error.value) == cli_error("render", missing, "-o", tmp_path / "x.png")

    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(raster.Error) as error:
        raster.Scene.load(bad)
    assert "raster: error: " + str(error.value) == cli_error("render", bad, "-o", tmp_path / "x.png")

    # A setting is named by its key here and by its option on the command line; the rest is the same.
    with pytest.raises(raster.Error) as error:
        vulkan.render(raster.Scene.load("builtin"), 8, 8, msaa=3)
    assert str(error.value) == "msaa 3 is not one of 1, 2, 4, 8, 16"
    assert cli_error("render", "builtin", "--msaa", 3, "-o", tmp_path / "x.png") == "raster: error: --msaa 3 is not one of 1, 2, 4, 8, 16"

    with pytest.raises(raster.Error) as error:
        vulkan.render(raster.Scene.load("builtin"), 8, 8, camera="orbit:1,2")
    assert "raster: error: " + str(error.value).replace("camera", "--camera", 1) == cli_error(
        "render", "builtin", "--camera", "orbit:1,2", "-o", tmp_path / "x.png")


def test_bad_input_raises_one_line_errors(vulkan):
    cases = [
        (lambda: raster.Renderer("metal"), "invalid backend 'metal'"),
        (lambda: vulkan.render(raster.Scene.load("builtin"), 8, 8, no_such_setting=1), "render: unknown setting 'no_such_setting'"),
        (lambda: vulkan.render(raster.Scene.load("builtin"), 8, 8, shading="pbr"), "shading"),
        (lambda: vulkan.render(raster.Scene.load("builtin"), 8, 8, camera=(np.eye(3), np.eye(4))), "4x4"),
        (lambda: raster.Scene.from_arrays(np.zeros((3, 2)), [[0, 1, 2]]), "positions must have shape (N, 3 or 4), not (3, 2)"),
        (lambda: raster.Scene.from_arrays(np.zeros((3, 3)), [[0.0, 1, 2]]), "indices must be integers"),
        (lambda: raster.Scene.from_arrays(np.zeros((3, 3)), [[0, 1, 2]], normals=np.zeros((2, 3))), "normals has 2 rows for 3 vertices"),
        (lambda: raster.Scene.from_arrays(np.eye(3), [[0, 1, 5]]), "no triangles, lines or points to draw"),
        # 2**32 + 1 must not wrap onto vertex 1, nor -1 onto the last vertex.
        (lambda: raster.Scene.from_arrays(np.eye(3), np.array([[0, 2, 2**32 + 1]], np.int64)),
         "no triangles, lines or points to draw"),
        (lambda: raster.Scene.from_arrays(np.eye(3), np.array([[0, 1, -1]], np.int32)),
         "no triangles, lines or points to draw"),
        (lambda: raster.rasterize(np.zeros((3, 3)), [[0, 1, 2]], (4, 4)), "pos must have shape"),
        (lambda: raster.rasterize(np.zeros((3, 4)), [[0, 1, 3]], (4, 4)), "tri indexes vertex 3 of 3"),
    ]
    for call, text in cases:
        with pytest.raises(raster.Error) as error:
            call()
        assert text in str(error.value) and "\n" not in str(error.value)


def test_a_mistyped_setting_names_the_nearest_one(vulkan):
    scene = raster.Scene.load("builtin")
    cases = [
        (dict(shadng="phong"), "render: unknown setting 'shadng'; did you mean 'shading'?"),
        (dict(Msaa=4), "render: unknown setting 'Msaa'; did you mean 'msaa'?"),
        (dict(cul="none"), "render: unknown setting 'cul'; did you mean 'cull'?"),
        (dict(xyzzy=1), "render: unknown setting 'xyzzy' (raster.SETTINGS lists them)"),
    ]
    for settings, message in cases:
        with pytest.raises(raster.Error) as error:
            vulkan.render(scene, 8, 8, **settings)
        assert str(error.value) == message
    with pytest.raises(raster.Error) as error:
        vulkan.render_many(scene, 8, 8, ["auto"], texture_filtr="nearest")
    assert str(error.value) == "render_many: unknown setting 'texture_filtr'; did you mean 'texture_filter'?"
    # Every key the schema lists is taken as it is.
    keys = {s["key"] for s in raster.SETTINGS} - {"width", "height", "camera"}
    assert "shading" in keys and "cull" in keys and "texture_filter" in keys


def test_dir_shows_the_api_alone():
    assert dir(raster) == sorted(raster.__all__)
    for name in ("np", "json", "os", "Any", "Dict", "dataclass", "threading"):
        assert name not in dir(raster)
    assert all(hasattr(raster, name) for name in raster.__all__)


def test_every_bad_input_is_a_raster_error_naming_the_value(vulkan):
    # The campaign's Python inputs: each raised something other than raster.Error, was taken wrongly, or
    # named the value wrongly. Every one is a one-line raster.Error now, checked before any allocation.
    scene = raster.Scene.load("builtin")
    tri = np.array([[-1, -1, 0.5, 1], [1, -1, 0.5, 1], [0, 1, 0.5, 1]], np.float32)
    rast = raster.rasterize(tri, [[0, 1, 2]], (8, 8))
    cases = [
        (lambda: vulkan.render(scene, np.float32(32.7), 16), "width must be a non-negative integer, not 32.7"),
        (lambda: vulkan.render(scene, True, 16), "width must be a non-negative integer, not true"),
        (lambda: vulkan.render(scene, 2**31, 16), "width 2147483648 is outside 1..16384"),
        (lambda: vulkan.render(scene, -4, 16), "width must be a non-negative integer, not '-4'"),
        (lambda: vulkan.render(scene, 16, 16, ambient=float("nan")), "ambient nan is not a finite number"),
        (lambda: vulkan.render(scene, 16, 16, light_dir=(1, float("inf"), 0)), "light_dir 1,inf,0 is not three finite"),
        (lambda: vulkan.render(None, 16, 16), "render: scene must be a raster.Scene, not None"),
        (lambda: raster.rasterize(tri, [[0, 1, 2]], (-8, 8)), "the height must be an integer in 1..16384, not -8"),
        (lambda: raster.rasterize(tri, [[0, 1, 2]], (100000, 100000)), "not 100000"),
        (lambda: raster.rasterize(tri, [[0, 1, 2]], (8.5, 8)), "not 8.5"),
        (lambda: raster.interpolate(np.ones((3, 2)), rast, np.zeros((0, 3), np.int32)),
         "rast[..., 3] holds 1.0, not a triangle id + 1 of the 0 triangles"),
        (lambda: raster.interpolate(np.ones((2, 2)), rast, [[0, 1, 2]]), "tri indexes vertex 2, but attr has 2 rows"),
        (lambda: raster.Scene.from_arrays(tri[:, :3], [[0, 1, 2]], colors=np.full((3, 3), np.nan)),
         "colors has a non-finite value in row 0"),
        (lambda: raster.Scene.from_arrays(tri[:, :3], [[0, 1, 2]], base_color=(1, float("nan"), 1, 1)),
         "base colour must be finite"),
        (lambda: raster.Scene.from_arrays(tri[:, :3].astype(np.complex64), [[0, 1, 2]]), "not complex64"),
        (lambda: raster.Scene.from_arrays(tri[:, :3].astype(str), [[0, 1, 2]]), "must hold real numbers, not <U"),
        (lambda: raster.Scene.from_arrays(tri[:, :3] > 0, [[0, 1, 2]]), "must hold real numbers, not bool"),
        (lambda: raster.Scene.from_arrays(np.array([[1, 2, 3], [4, 5], [6]], dtype=object), [[0, 1, 2]]),
         "not object"),
        (lambda: raster.Scene.from_arrays(tri[:, :3], [[True, False, True]]), "indices must be integers, not bool"),
        (lambda: vulkan.render(scene, 16, 16, **{"k" * 10_000_000: 1}), "... (10000000 bytes)"),
        (lambda: vulkan.render(scene, 16, 16, shading="x" * 10_000_000), "... (10000000 bytes)"),
    ]
    for call, text in cases:
        with pytest.raises(raster.Error) as error:
            call()
        message = str(error.value)
        assert text in message and "\n" not in message and len(message) < 2000, message[:300]
    # NumPy scalars are the numbers they hold.
    a = vulkan.render(scene, np.int32(24), np.int64(16), msaa=np.int64(4), ao="gtao", ao_radius=np.float32(0.5))
    b = vulkan.render(scene, 24, 16, msaa=4, ao="gtao", ao_radius=0.5)
    assert (a.width, a.height) == (24, 16) and a.stats["settings"]["msaa"] == 4
    np.testing.assert_array_equal(a.color, b.color)


def test_the_documented_maximum_is_accepted(vulkan):
    frame = vulkan.render(raster.Scene.load("builtin"), 8, 8, ao="gtao", ao_radius=1e20)
    assert frame.stats["settings"]["ao_radius"] == pytest.approx(1e20)


def test_dropped_primitives_keep_their_ids_and_warn(backend):
    # A triangle with an index out of range and one with a NaN corner are drawn by nothing but keep their
    # ids, so that the ids name rows of the caller's arrays (the campaign's shifted down past each);
    # the warning arrives through Python's warnings.
    positions = np.array([[-1, -1, 0.5], [0, -1, 0.5], [0, 1, 0.5], [-1, 1, 0.5],
                          [0, -1, 0.5], [1, -1, 0.5], [1, 1, 0.5], [0, 1, 0.5], [np.nan, 0, 0]], np.float32)
    triangles = np.array([[0, 1, 99], [0, 1, 2], [4, 5, 8], [0, 2, 3], [4, 5, 6], [4, 6, 7]], np.int64)
    with pytest.warns(raster.RasterWarning, match="dropped 2 triangle"):
        scene = raster.Scene.from_arrays(positions, triangles, double_sided=True)
    assert scene.triangle_count == 6
    ids = set(np.unique(renderer(backend).render(scene, 16, 16, (np.eye(4), np.eye(4))).ids).tolist())
    assert ids == {1, 3, 4, 5}
    rast = raster.rasterize(np.concatenate([positions, np.ones((9, 1), np.float32)], 1)[:8],
                            triangles[[1, 3, 4, 5]], (16, 16), backend=backend)
    assert set(np.unique(rast[..., 3]).tolist()) == {1.0, 2.0, 3.0, 4.0}  # the kept four fill the view


# ---- scenes from arrays ------------------------------------------------------------------------------

def wavy_grid(n=12):
    """A procedural height field: (positions (N, 3) float32, triangles (T, 3) int32)."""
    u, v = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n))
    y = 0.25 * np.sin(3 * u) * np.cos(2 * v)
    positions = np.stack([u, y, v], axis=-1).reshape(-1, 3).astype(np.float32)
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1], i[:-1, 1:], i[1:, :-1], i[1:, 1:]
    triangles = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)]).reshape(-1, 3)
    return positions, triangles.astype(np.int32)


def test_from_arrays_renders_as_the_same_obj(backend, tmp_path):
    positions, triangles = wavy_grid()
    obj = tmp_path / "grid.obj"
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in positions.tolist()) +
                   "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles.tolist()))
    r = renderer(backend)
    from_arrays = r.render(raster.Scene.from_arrays(positions, triangles), 64, 64, "orbit:30,35,3.5", cull="none")
    from_file = r.render(raster.Scene.load(obj), 64, 64, "orbit:30,35,3.5", cull="none")
    covered = from_file.ids != raster.EMPTY_ID
    assert covered.sum() > 1000
    np.testing.assert_array_equal(from_arrays.ids, from_file.ids)
    np.testing.assert_array_equal(from_arrays.depth, from_file.depth)


def test_from_arrays_lines_points_colors_texture(vulkan):
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    texture = np.zeros((2, 2, 3), np.uint8)
    texture[0, :, 0] = 255  # top row red, bottom row green
    texture[1, :, 1] = 255
    scene = raster.Scene.from_arrays(positions, [[0, 1, 2], [0, 2, 3]], uv=positions[:, :2] * 0.5 + 0.5,
                                     colors=np.ones((4, 3)), texture=texture, lines=[[0, 2]], points=[1])
    assert (scene.triangle_count, scene.line_count, scene.point_count) == (2, 1, 1)
    frame = vulkan.render(scene, 32, 32, "orbit:0,0,3", shading="texcoord", texture_filter="nearest")
    assert set(np.unique(frame.ids)) <= {0, 1, 2, 3, raster.EMPTY_ID}


# ---- rasterize, interpolate ---------------------------------------------------------------------------

def edge(a, b, x, y):
    return (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])


def analytic(pos, res):
    """Pixel-centre coverage, barycentrics (perspective-correct) and z/w of one clip-space triangle, in
    float64, and the pixels whose centre is too close to an edge for the 1/256-px snapping to decide."""
    h, w = res
    y, x = np.mgrid[0:h, 0:w]
    x = (x + 0.5) / w * 2 - 1
    y = (y + 0.5) / h * 2 - 1
    p = pos[:, :2] / pos[:, 3:4]
    area = edge(p[0], p[1], p[2][0], p[2][1])
    l0, l1, l2 = (edge(p[1], p[2], x, y) / area, edge(p[2], p[0], x, y) / area, edge(p[0], p[1], x, y) / area)
    inside = (l0 > 0) & (l1 > 0) & (l2 > 0)
    # Distance of the centre to each edge in pixels: l_i * (twice the area) / edge length, in px.
    scale = np.array([w / 2, h / 2])
    lengths = [np.linalg.norm((p[(i + 2) % 3] - p[(i + 1) % 3]) * scale) for i in range(3)]
    px_area = abs(area) * (w / 2) * (h / 2)
    near = np.min([np.abs(l) * px_area / length for l, length in zip((l0, l1, l2), lengths)], axis=0) < 1 / 64
    pw = np.stack([l0 / pos[0, 3], l1 / pos[1, 3], l2 / pos[2, 3]])
    bary = pw / pw.sum(axis=0)
    zw = l0 * pos[0, 2] / pos[0, 3] + l1 * pos[1, 2] / pos[1, 3] + l2 * pos[2, 2] / pos[2, 3]
    return inside, near, bary, zw


TRIANGLES = [
    np.array([[-0.8, -0.7, 0.25, 1], [0.9, -0.5, 0.25, 1], [-0.3, 0.85, 0.25, 1]]),
    np.array([[0.7, 0.8, -0.5, 1], [-0.9, 0.1, 0.0, 1], [0.2, -0.9, 0.75, 1]]),  # clockwise, sloped
    np.array([[-1.2, -0.6, 0.2, 2.0], [0.6, -0.3, -0.4, 1.0], [0.1, 1.5, 1.0, 3.0]]),  # perspective
]


@pytest.mark.parametrize("index", range(len(TRIANGLES)))
def test_rasterize_matches_analytic_triangles(backend, index):
    pos = TRIANGLES[index].astype(np.float32)
    res = (40, 56)
    rast = raster.rasterize(pos, np.array([[0, 1, 2]], np.int32), res, backend=backend)
    assert rast.shape == (1, 40, 56, 4) and rast.dtype == np.float32
    inside, near, bary, zw = analytic(pos.astype(np.float64), res)
    covered = rast[0, ..., 3] == 1
    assert inside.sum() > 200
    np.testing.assert_array_equal(covered[~near], inside[~near])
    assert ((rast[0, ..., 3] == 0) | covered).all()
    assert (rast[0][~covered] == 0).all()
    np.testing.assert_allclose(rast[0, covered, 0], bary[0][covered], atol=2e-6, rtol=0)
    np.testing.assert_allclose(rast[0, covered, 1], bary[1][covered], atol=2e-6, rtol=0)
    # Depth is interpolated over the vertices as snapped to 1/256 px (as a GPU does), the barycentrics
    # are computed at the exact centre: z/w may differ from the analytic plane by its change over 1/256 px.
    snap = (np.abs(np.diff(zw, axis=1)).max() + np.abs(np.diff(zw, axis=0)).max()) / 256
    np.testing.assert_allclose(rast[0, covered, 2], zw[covered], atol=snap + 2e-6, rtol=0)
    if index == 0:
        # Constant depth: z/w is exactly the vertices' (0.25), not merely close.
        assert (rast[0, covered, 2] == np.float32(0.25)).all()


def test_rasterize_equals_the_c_api_ids(backend):
    pos = np.concatenate(TRIANGLES).astype(np.float32)
    tri = np.arange(9, dtype=np.int32).reshape(3, 3)
    rast = raster.rasterize(pos, tri, (40, 56), backend=backend)
    # The same clip-space triangles as a scene of homogeneous positions seen through identity matrices,
    # OpenGL's depth mapped to Vulkan's: the C++ API's ids and depth.
    gl_to_vk = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0.5, 0.5], [0, 0, 0, 1]], np.float32)
    scene = raster.Scene.from_arrays(pos, tri, normals=np.zeros((9, 3)))
    frame = renderer(backend).render(scene, 56, 40, (np.eye(4), gl_to_vk), cull="none")
    ids = np.where(frame.ids == raster.EMPTY_ID, 0, frame.ids.astype(np.int64) + 1)
    np.testing.assert_array_equal(rast[0, ..., 3], ids)
    covered = ids > 0
    np.testing.assert_array_equal(rast[0, covered, 2], 2 * frame.depth[covered] - 1)


def test_rasterize_shared_edge_through_pixel_centres_is_covered_once(backend):
    # A square split along its diagonal, which passes through pixel centres (x = y); the top-left rule
    # gives every centre on it to exactly one of the two triangles.
    n = 32
    pos = np.array([[-0.75, -0.75, 0, 1], [0.75, -0.75, 0, 1], [0.75, 0.75, 0, 1], [-0.75, 0.75, 0, 1]], np.float32)
    first = raster.rasterize(pos, [[0, 1, 2]], (n, n), backend=backend)[0, ..., 3] > 0
    second = raster.rasterize(pos, [[0, 2, 3]], (n, n), backend=backend)[0, ..., 3] > 0
    both = raster.rasterize(pos, [[0, 1, 2], [0, 2, 3]], (n, n), backend=backend)[0, ..., 3]
    assert not (first & second).any()
    assert (first | second).sum() == 24 * 24
    np.testing.assert_array_equal(both, np.where(first, 1, np.where(second, 2, 0)))
    diagonal = np.arange(4, 28)
    assert (first | second)[diagonal, diagonal].all()


def test_rasterize_batches_and_row_order():
    pos = TRIANGLES[0].astype(np.float32)
    below = pos.copy()
    below[:, 1] = np.abs(below[:, 1]) * 0.5 + 0.4  # NDC y > 0: the lower half of the rows
    rast = raster.rasterize(np.stack([pos, below]), [[0, 1, 2]], (32, 32), backend="vulkan")
    assert rast.shape == (2, 32, 32, 4)
    np.testing.assert_array_equal(rast[0], raster.rasterize(pos, [[0, 1, 2]], (32, 32), backend="vulkan")[0])
    rows = np.nonzero(rast[1, ..., 3].any(axis=1))[0]
    assert rows.min() >= 16  # row 0 is NDC y = -1
    assert raster.rasterize(pos, np.zeros((0, 3), np.int32), (4, 4)).shape == (1, 4, 4, 4)


def test_rasterize_msaa(backend):
    pos = TRIANGLES[1].astype(np.float32)
    one = raster.rasterize(pos, [[0, 1, 2]], (32, 32), backend=backend)
    four = raster.rasterize(pos, [[0, 1, 2]], (32, 32), backend=backend, msaa=4)
    # Sample 0 of Vulkan's 4x pattern is off the centre: coverage differs only at the edges.
    assert (one[0, ..., 3] != four[0, ..., 3]).sum() < 0.1 * (one[0, ..., 3] > 0).sum()


def test_interpolate_reproduces_barycentrics_and_positions():
    pos = TRIANGLES[2].astype(np.float32)
    tri = np.array([[0, 1, 2]], np.int32)
    rast = raster.rasterize(pos, tri, (24, 32), backend="vulkan")
    out = raster.interpolate(np.eye(3, dtype=np.float32), rast, tri)
    assert out.shape == (1, 24, 32, 3) and out.dtype == np.float32
    covered = rast[0, ..., 3] > 0
    np.testing.assert_allclose(out[0, covered, 0], rast[0, covered, 0], atol=1e-7)
    np.testing.assert_allclose(out[0, covered, 1], rast[0, covered, 1], atol=1e-7)
    np.testing.assert_allclose(out[0, covered].sum(-1), 1, atol=1e-6)
    assert (out[0, ~covered] == 0).all()
    # Perspective-correct interpolation of clip x and w gives x/w = the pixel centre's NDC x.
    xw = raster.interpolate(pos[None, :, [0, 3]], rast, tri)
    ndc_x = (np.arange(32) + 0.5) / 32 * 2 - 1
    np.testing.assert_allclose(xw[0, covered, 0] / xw[0, covered, 1], np.broadcast_to(ndc_x, (24, 32))[covered],
                               atol=2e-5)


# ---- sessions --------------------------------------------------------------------------------------

def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_a_session_renders_100_frames_without_growing(vulkan):
    scene = raster.Scene.load("builtin")
    for _ in range(10):
        vulkan.render(scene, 64, 64, surface_aovs=True)
    before = rss_bytes()
    for i in range(100):
        frame = vulkan.render(scene, 64, 64, f"orbit:{3.6 * i},20,4", surface_aovs=True)
        assert frame.ids.shape == (64, 64)
    grown = rss_bytes() - before
    # One frame's host buffers are ~100 kB; a leak of one per frame would add ~10 MB.
    assert grown < 2 * 1024 * 1024, grown


def test_render_releases_the_gil(vulkan):
    scene = raster.Scene.load("builtin:dense")
    vulkan.render(scene, 256, 256)
    count = 0
    thread = threading.Thread(target=vulkan.render, args=(scene, 256, 256), kwargs={"repeat": 3})
    thread.start()
    while thread.is_alive():
        count += 1
    thread.join()
    assert count > 10000, count


def test_renderer_keeps_its_scenes(vulkan):
    scenes = [raster.Scene.load("builtin") for _ in range(6)]
    for s in scenes:
        vulkan.render(s, 8, 8)
    assert vulkan._native.session_count == 4  # the last four scenes
    vulkan.release()
    assert vulkan._native.session_count == 0


def test_a_renderer_draws_each_of_its_scenes(backend):
    # Scenes that differ in triangle count, textures, vertex colours and level of detail, drawn by one
    # Renderer in turn (more of them than it keeps sessions for): each frame equals the scene's first,
    # which a new session draws right after uploading its scene. The campaign's finding was builtin after
    # builtin:dense covering 2 pixels instead of 357, silently.
    r = renderer(backend)
    positions = np.array([[-1, -1, 0.5], [1, -1, 0.5], [0, 1, 0.5]], np.float32)
    scenes = [
        (raster.Scene.load("builtin"), {}),
        (raster.Scene.load("builtin:dense"), {}),
        (raster.Scene.load("builtin:checker"), {"texture_filter": "trilinear"}),
        (raster.Scene.from_arrays(positions, [[0, 1, 2]], colors=np.eye(3, dtype=np.float32),
                                  double_sided=True), {}),
        (raster.Scene.load("builtin:lowpoly"), {"lod": "on", "lod_error_px": 4}),
        (raster.Scene.load("builtin:lowpoly"), {"tessellate": "pn"}),
    ]
    first = [r.render(scene, 48, 40, **kw) for scene, kw in scenes]
    assert len({int((f.ids != raster.EMPTY_ID).sum()) for f in first}) > 1
    for k in [0, 5, 1, 0, 4, 2, 3, 0]:
        scene, kw = scenes[k]
        again = r.render(scene, 48, 40, **kw)
        np.testing.assert_array_equal(again.ids, first[k].ids, err_msg=f"scene {k}")
        np.testing.assert_array_equal(again.depth, first[k].depth, err_msg=f"scene {k}")
        np.testing.assert_array_equal(again.color, first[k].color, err_msg=f"scene {k}")


# ---- compare, testing helpers ------------------------------------------------------------------------

def test_compare_frames_and_files(vulkan, tmp_path):
    scene = raster.Scene.load("builtin")
    a = vulkan.render(scene, W, H, surface_aovs=True)
    b = vulkan.render(scene, W, H, surface_aovs=True)
    report = raster.compare(a, b)
    assert report["passed"] and report["kind"] == "both" and report["id_mismatches"] == 0
    assert report["psnr"] == float("inf") and report["max_bary_diff"] == 0
    b.color[3, 4, 1] = b.color[3, 4, 1] + 9 if b.color[3, 4, 1] < 128 else b.color[3, 4, 1] - 9
    b.depth[tuple(np.argwhere(b.ids != raster.EMPTY_ID)[0])] += 0.25
    color = raster.compare(a, b, what="color", tolerance=8)
    assert not color["passed"] and color["max_error"] == 9 and color["max_error_at"] == (4, 3)
    assert raster.compare(a, b, what="color", tolerance=9)["passed"]
    aov = raster.compare(a, b, what="aov")
    assert not aov["passed"] and aov["max_depth_diff"] == pytest.approx(0.25, abs=1e-6)
    # Files: the command line's own report for its own images.
    for name in ("x", "y"):
        run_cli("render", "builtin", "--backend", "vulkan", "--width", W, "--height", H, "-q", "-o",
                tmp_path / f"{name}.png", "--aov", tmp_path / f"{name}.exr")
    for ext in ("png", "exr"):
        files = raster.compare(tmp_path / f"x.{ext}", tmp_path / f"y.{ext}")
        _, out, _ = run_cli("compare", tmp_path / f"x.{ext}", tmp_path / f"y.{ext}")
        assert files["passed"] and files["text"] in out


def test_assert_frames_agree_fails_on_a_real_difference(vulkan):
    scene = raster.Scene.load("builtin")
    reference = vulkan.render(scene, W, H, msaa=4, aov_samples=True)
    altered = vulkan.render(scene, W, H, msaa=4, aov_samples=True)
    raster.testing.assert_frames_agree(reference, altered)
    covered = np.argwhere(altered.ids != raster.EMPTY_ID)[0]
    altered.ids[tuple(covered)] += 1
    with pytest.raises(AssertionError) as failure:
        raster.testing.assert_frames_agree(reference, altered)
    assert "Id mismatches: 1 " in str(failure.value) and "FAILURE" in str(failure.value)
    altered.ids[tuple(covered)] -= 1
    sample = tuple(np.argwhere(altered.sample_ids != raster.EMPTY_ID)[-1])
    altered.sample_depth[sample] -= 0.5
    with pytest.raises(AssertionError) as failure:
        raster.testing.assert_frames_agree(reference, altered)
    assert "1 over depth tolerance" in str(failure.value)
    altered.sample_depth[sample] += 0.5
    altered.color[0, 0, 0] ^= 1
    raster.testing.assert_frames_agree(reference, altered, color_tolerance=1)
    with pytest.raises(AssertionError):
        raster.testing.assert_frames_agree(reference, altered, color_tolerance=0)


def test_assert_backends_agree_requires_its_backends(monkeypatch):
    scene = raster.Scene.load("builtin")
    monkeypatch.setenv("SR_ALLOW_MISSING_BACKENDS", "")
    try:
        raster.Renderer("cuda")
    except raster.Error:
        with pytest.raises(AssertionError, match="backend cuda is required but unavailable"):
            raster.testing.assert_backends_agree(scene, ("cuda", "vulkan"), width=16, height=16)
        return
    raster.testing.assert_backends_agree(scene, ("cuda", "vulkan"), width=16, height=16)


# ---- examples ---------------------------------------------------------------------------------------

EXAMPLES = SOURCE_DIR / "examples" / "python"


@pytest.mark.parametrize("args", [
    ["render_gltf.py", str(SOURCE_DIR / "assets" / "hierarchy.gltf"), "{tmp}/out.png", "--width", "32", "--height", "24",
     "--backend", "vulkan"],
    ["turntable.py", "builtin", "{tmp}/turntable.npy", "--frames", "3", "--size", "24", "--backend", "vulkan"],
    ["arrays.py", "{tmp}/arrays.npz", "--size", "32", "--backend", "vulkan"],
    ["benchmark.py", "--scene", "builtin", "--width", "32", "--height", "24", "--runs", "3", "--warmup", "1",
     "--backends", "vulkan"],
])
def test_examples_run(args, tmp_path):
    command = [sys.executable, str(EXAMPLES / args[0])] + [a.format(tmp=tmp_path) for a in args[1:]]
    done = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()
