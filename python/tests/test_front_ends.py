"""One frame, every front end (issue 45): the Python module's Frame.save writes the PNG, the EXR (every
sample's id and depth included) and the statistics that `raster render` writes for the same scene and
settings, byte for byte, for the cases of tests/front_ends/every_setting.jsonl, which between them set
every setting of the schema away from its default (tests/front_ends_test.cpp checks that, and the
command line against a manifest and the C++ API)."""

import json

import pytest

import raster
from conftest import SOURCE_DIR, renderer, run_cli

BASE = {"width": 48, "height": 32, "msaa": 1, "warmup": 0, "repeat": 1}


def cases():
    lines = (SOURCE_DIR / "tests" / "front_ends" / "every_setting.jsonl").read_text().splitlines()
    out = []
    for line in filter(None, lines):
        given = json.loads(line)
        scene = given.pop("scene", "builtin")
        out.append((scene, {**BASE, **given}))
    return out


def option_text(value):
    if isinstance(value, list):
        return ",".join(option_text(v) for v in value)
    return str(value) if not isinstance(value, float) else repr(value)


def comparable_stats(path):
    """Everything but the times, and what the device's history sets (peak memory, grown capacities)."""
    stats = json.loads(path.read_text())
    for key in ("stages_ms", "gpu_total_ms", "peak_device_bytes", "capacities"):
        stats.pop(key)
    stats.get("lod", {}).pop("build_ms", None)
    return stats


@pytest.mark.parametrize("scene,settings", cases(), ids=lambda v: v if isinstance(v, str) else None)
def test_frame_save_writes_what_raster_render_writes(scene, settings, tmp_path):
    renderer("vulkan")
    args = ["render", scene, "--backend", "vulkan", "-q", "-o", tmp_path / "cli.png", "--aov",
            tmp_path / "cli.exr", "--stats", tmp_path / "cli.json"]
    for key, value in settings.items():
        option = "--" + key.replace("_", "-")
        if isinstance(value, bool):
            args += [option] if value else []
        else:
            args += [option, option_text(value)]
    run_cli(*args)

    keywords = {k: v for k, v in settings.items() if k not in ("width", "height")}
    # A Renderer of its own: the statistics count the frame's redraws, which a shared one's earlier
    # frames would have spared it.
    frame = raster.Renderer("vulkan").render(raster.Scene.load(scene), settings["width"], settings["height"],
                                             surface_aovs=True, **keywords)
    for name in ("py.png", "py.exr", "py.json"):
        frame.save(tmp_path / name)
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    assert (tmp_path / "py.exr").read_bytes() == (tmp_path / "cli.exr").read_bytes()
    assert comparable_stats(tmp_path / "py.json") == comparable_stats(tmp_path / "cli.json")


def test_frame_save_refuses_what_it_cannot_write(tmp_path):
    frame = renderer("vulkan").render(raster.Scene.load("builtin"), 16, 16, outputs=("ids",))
    with pytest.raises(raster.Error, match=r"^save: the path must end in \.png .*/x\.bmp'$"):
        frame.save(tmp_path / "x.bmp")
    with pytest.raises(raster.Error, match=r"^save: the frame has no colour image"):
        frame.save(tmp_path / "x.png")
    with pytest.raises(raster.Error, match=r"^save: an \.exr holds the ids and depth"):
        frame.save(tmp_path / "x.exr")
    with pytest.raises(raster.Error, match=r"png_compression"):
        renderer("vulkan").render(raster.Scene.load("builtin"), 16, 16).save(tmp_path / "x.png",
                                                                              png_compression="tiny")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("kwargs,expected", [
    ({"camera": "orbit:bad"}, "invalid camera 'orbit:bad': expected auto, gltf:N or orbit:"),
    ({"camera": "gltf:5"}, "camera gltf:5: the scene has 0 camera(s)"),
    ({"model": "spin:3"}, "invalid model 'spin:3': unknown part 'spin'"),
])
def test_camera_and_model_errors_name_the_keywords(kwargs, expected):
    """The library names the camera and the model as the caller did: keywords here, not the command
    line's --camera and --model (which `raster render` keeps)."""
    with pytest.raises(raster.Error) as caught:
        renderer("vulkan").render(raster.Scene.load("builtin"), 16, 16, **kwargs)
    assert str(caught.value).startswith(expected) and "--" not in str(caught.value)
    option, value = next(iter(kwargs.items()))
    code, _, err = run_cli("render", "--backend", "vulkan", "-q", "-o", "/dev/null.png", f"--{option}", value,
                           check=False)
    assert code == 2 and f"--{option}" in err
