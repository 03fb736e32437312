"""What a caller receives and how: rasterize's output computed on the device against the frames'
own ids, depth and barycentrics (the form it was assembled from on the host before), a batch against
its views drawn one by one, positions replaced in place against a scene made from them, only the images
asked for, interpolate against its definition in numpy, and host frames handed to other libraries
through DLPack without a copy (numpy and Debian's torch)."""

import numpy as np
import pytest

import raster
from conftest import renderer

# rasterize's camera: identity view, OpenGL's depth range mapped to Vulkan's.
GL_TO_VK = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0.5, 0.5], [0, 0, 0, 1]], np.float32)


def mesh(views, seed=1):
    """A 12 x 12 grid of clip-space quads (288 triangles) seen `views` ways: per view its own
    perspective tilt and offset, some of it outside the view."""
    rng = np.random.default_rng(seed)
    n = 12
    y, x = np.mgrid[0:n + 1, 0:n + 1] / n * 2.2 - 1.1
    tri = []
    for j in range(n):
        for i in range(n):
            v = j * (n + 1) + i
            tri += [[v, v + 1, v + n + 2], [v, v + n + 2, v + n + 1]]
    pos = np.zeros((views, x.size, 4), np.float32)
    for b in range(views):
        w = 1.0 + 0.4 * rng.random() * (x.ravel() + 1.1)
        pos[b, :, 0] = (x.ravel() + 0.2 * rng.standard_normal()) * w
        pos[b, :, 1] = (y.ravel() + 0.1 * rng.standard_normal()) * w
        pos[b, :, 2] = (0.3 * np.sin(3 * x.ravel() + b) * y.ravel()) * w
        pos[b, :, 3] = w
    return pos, np.array(tri, np.int32)


def host_rast(frame):
    """rasterize's output assembled on the host from a frame's ids, depth and surface AOVs, as the
    module did before the device computed it."""
    ids, depth, bary = frame.ids, frame.depth, frame.bary
    covered = ids != raster.EMPTY_ID
    out = np.zeros(ids.shape + (4,), np.float32)
    out[..., 0] = np.where(covered, np.float32(1) - bary[..., 0] - bary[..., 1], 0)
    out[..., 1] = bary[..., 0]
    out[..., 2] = np.where(covered, np.float32(2) * depth - np.float32(1), 0)
    out[..., 3] = np.where(covered, ids.astype(np.float32) + np.float32(1), 0)
    return out


def test_rasterize_equals_the_frames_ids_depth_and_barycentrics(backend):
    pos, tri = mesh(3)
    r = renderer(backend)
    rast = raster.rasterize(pos, tri, (48, 64), renderer=r)
    assert (rast[..., 3] > 0).sum() > 3 * 48 * 64 // 2
    for b in range(3):
        scene = raster.Scene.from_arrays(pos[b], tri, normals=np.zeros((pos.shape[1], 3)))
        frame = r.render(scene, 64, 48, (np.eye(4), GL_TO_VK), cull="none", shading="id", surface_aovs=True)
        np.testing.assert_array_equal(rast[b].view(np.uint32), host_rast(frame).view(np.uint32))


def test_a_batch_equals_its_views_one_by_one_and_a_moved_topology_draws_anew(backend):
    pos, tri = mesh(4, seed=2)
    r = renderer(backend)
    batch = raster.rasterize(pos, tri, (40, 40), renderer=r, msaa=4)
    for b in range(4):
        one = raster.rasterize(pos[b], tri, (40, 40), renderer=r, msaa=4)
        np.testing.assert_array_equal(batch[b].view(np.uint32), one[0].view(np.uint32))
    # The same topology again (the scene kept, its positions replaced), then another one.
    again = raster.rasterize(pos[::-1], tri, (40, 40), renderer=r, msaa=4)
    np.testing.assert_array_equal(again.view(np.uint32), batch[::-1].view(np.uint32))
    fewer = raster.rasterize(pos[0], tri[::2], (40, 40), renderer=r, msaa=4)
    ids = fewer[0, ..., 3]
    assert set(np.unique(ids)) <= {0} | set(range(1, len(tri[::2]) + 1))
    assert (ids > 0).sum() < (batch[0, ..., 3] > 0).sum()


def test_update_positions_equals_a_scene_made_from_them(backend):
    pos, tri = mesh(2, seed=3)
    world = [p[:, :3] / p[:, 3:] for p in pos]
    r = renderer(backend)
    kwargs = dict(camera="orbit:10,20,3.5", clusters="on")
    scene = raster.Scene.from_arrays(world[0], tri, double_sided=True)  # flat normals, from the positions
    first = r.render(scene, 64, 48, **kwargs)
    scene.update_positions(world[1])
    moved = r.render(scene, 64, 48, **kwargs)
    fresh = r.render(raster.Scene.from_arrays(world[1], tri, double_sided=True), 64, 48, **kwargs)
    for name in ("color", "ids", "depth"):
        np.testing.assert_array_equal(getattr(moved, name), getattr(fresh, name), err_msg=name)
    assert (moved.ids != first.ids).any()
    with pytest.raises(raster.Error, match="update_positions: 168 positions of 3 components for a scene made from 169"):
        scene.update_positions(world[1][:-1])
    bad = world[1].copy()
    bad[5, 1] = np.inf
    with pytest.raises(raster.Error, match="vertex 5 is not finite"):
        scene.update_positions(bad)
    with pytest.raises(raster.Error, match="only a scene made from arrays"):
        raster.Scene.load("builtin").update_positions(world[1])


def test_only_the_images_asked_for(vulkan):
    scene = raster.Scene.load("builtin")
    every = vulkan.render(scene, 80, 60)
    ids = vulkan.render(scene, 80, 60, outputs=("ids",))
    assert ids.color is None and ids.depth is None
    np.testing.assert_array_equal(ids.ids, every.ids)
    colour = vulkan.render(scene, 80, 60, outputs=["color"])
    assert colour.ids is None and colour.depth is None
    np.testing.assert_array_equal(colour.color, every.color)
    np.testing.assert_array_equal(vulkan.render(scene, 80, 60, outputs={"depth"}).depth, every.depth)
    with pytest.raises(raster.Error, match="unknown output 'colour'"):
        vulkan.render(scene, 80, 60, outputs=("colour",))
    with pytest.raises(raster.Error, match="outputs must be a sequence of names"):
        vulkan.render(scene, 80, 60, outputs="ids")


def numpy_interpolate(attr, rast, tri):
    """nvdiffrast's interpolate in numpy, in float32, in the order the module's documentation gives."""
    ids = rast[..., 3].astype(np.int64) - 1
    covered = ids >= 0
    corners = tri[np.where(covered, ids, 0)]
    a = attr[corners] if attr.ndim == 2 else attr[np.arange(attr.shape[0])[:, None, None, None], corners]
    u, v = rast[..., 0:1], rast[..., 1:2]
    out = u * a[..., 0, :] + v * a[..., 1, :] + (np.float32(1) - u - v) * a[..., 2, :]
    out[~covered] = 0
    return out.astype(np.float32)


def test_interpolate_equals_its_definition_bit_for_bit(vulkan):
    pos, tri = mesh(2, seed=4)
    rast = raster.rasterize(pos, tri, (36, 44), renderer=vulkan)
    rng = np.random.default_rng(5)
    shared = rng.standard_normal((pos.shape[1], 5)).astype(np.float32)
    per_view = rng.standard_normal((2, pos.shape[1], 3)).astype(np.float32)
    for attr in (shared, per_view):
        got = raster.interpolate(attr, rast, tri)
        np.testing.assert_array_equal(got.view(np.uint32), numpy_interpolate(attr, rast, tri).view(np.uint32))
    broken = rast.copy()
    broken[1, 7, 9, 3] = 2.5
    with pytest.raises(raster.Error, match=r"rast\[\.\.\., 3\] holds 2\.5, not a triangle id \+ 1"):
        raster.interpolate(shared, broken, tri)


def test_host_frames_go_to_dlpack_consumers_without_a_copy(vulkan):
    frame = vulkan.render(raster.Scene.load("builtin"), 48, 32)
    for name in ("color", "ids", "depth"):
        array = getattr(frame, name)
        assert array.__dlpack_device__() == (1, 0)  # kDLCPU, device 0
        shared = np.from_dlpack(array)
        assert shared.__array_interface__["data"][0] == array.__array_interface__["data"][0], name
        np.testing.assert_array_equal(shared, array)
    import torch  # Debian's python3-torch (ci/setup)
    # Torch before 2.3 (Debian 12 has 1.13) has no uint32: the ids go as the int32 view of their memory.
    for name in ("color", "ids", "depth"):
        array = getattr(frame, name)
        if name == "ids" and not hasattr(torch, "uint32"):
            array = array.view(np.int32)
        tensor = torch.from_dlpack(array)
        assert tensor.data_ptr() == array.__array_interface__["data"][0], name
        np.testing.assert_array_equal(tensor.numpy(), array)


def test_torch_tensors_on_the_host_in_and_out(vulkan):
    """rasterize and interpolate of torch CPU tensors (one recording gradients among them) return torch
    tensors over the module's own output memory, equal to the numpy path."""
    import torch  # Debian's python3-torch (ci/setup)
    pos, tri = mesh(2, seed=12)
    tpos = torch.from_numpy(pos).requires_grad_(True)
    rast = raster.rasterize(tpos, torch.from_numpy(tri), (24, 32), renderer=vulkan)
    expected = raster.rasterize(pos, tri, (24, 32), renderer=vulkan)
    assert isinstance(rast, torch.Tensor) and rast.device.type == "cpu" and rast.dtype == torch.float32
    np.testing.assert_array_equal(rast.numpy(), expected)
    attr = np.random.default_rng(12).standard_normal((pos.shape[1], 3)).astype(np.float32)
    got = raster.interpolate(torch.from_numpy(attr), rast, torch.from_numpy(tri))
    assert isinstance(got, torch.Tensor)
    np.testing.assert_array_equal(got.numpy(), raster.interpolate(attr, expected, tri))


def test_frames_on_the_device_equal_the_host_frames(backend):
    r = renderer(backend)
    scene = raster.Scene.load("builtin")
    host = r.render(scene, 64, 40)
    if backend != "cuda":
        with pytest.raises(raster.Error, match="on_device needs a CUDA device"):
            r.render(scene, 64, 40, on_device=True)
        return
    frame = r.render(scene, 64, 40, on_device=True)
    for name, typestr, shape in (("color", "<u1", (40, 64, 4)), ("ids", "<u4", (40, 64)), ("depth", "<f4", (40, 64))):
        array = getattr(frame, name)
        assert isinstance(array, raster.DeviceArray)
        interface = array.__cuda_array_interface__
        assert interface["shape"] == shape and interface["typestr"] == typestr and interface["version"] == 3
        assert interface["data"][0] == array.data_ptr != 0
        assert array.__dlpack_device__() == (2, r.device.index)  # kDLCUDA
        try:
            import torch
        except ImportError:
            continue  # the GPU machine's Python has torch; its check is the one below
        np.testing.assert_array_equal(torch.from_dlpack(array).cpu().numpy(), getattr(host, name))
    pos, tri = mesh(2, seed=6)
    on_gpu = raster.rasterize(pos, tri, (32, 48), renderer=r, on_device=True)
    assert on_gpu.shape == (2, 32, 48, 4)
    try:
        import torch
    except ImportError:
        return
    np.testing.assert_array_equal(torch.from_dlpack(on_gpu).cpu().numpy(),
                                  raster.rasterize(pos, tri, (32, 48), renderer=r))


def test_rasterize_reports_non_finite_positions_and_keeps_the_topology_sound(backend):
    """A view with a NaN corner raises raster.Error naming it (checked on the device, where the triangle
    is dropped); the topology's scene, made at the origin, drops nothing: the next call with finite
    positions equals a fresh renderer's."""
    r = renderer(backend)
    pos, tri = mesh(3, seed=8)
    bad = pos.copy()
    bad[1, 17, 2] = np.nan
    with pytest.raises(raster.Error, match=r"pos\[1\] has non-finite values"):
        raster.rasterize(bad, tri, (24, 24), renderer=r)
    bad[0, 0, 0] = np.inf
    with pytest.raises(raster.Error, match=r"pos\[0\] has non-finite values"):
        raster.rasterize(bad[:1], tri, (24, 24), renderer=r)
    fresh = raster.Renderer(backend)
    np.testing.assert_array_equal(raster.rasterize(pos, tri, (24, 24), renderer=r),
                                  raster.rasterize(pos, tri, (24, 24), renderer=fresh))


class _FakeGpuArray:
    """An object that says it is in CUDA memory (the CUDA array interface), for the checks made before
    any device reads it."""

    def __init__(self, shape, typestr="<f4", strides=None):
        self.__cuda_array_interface__ = {"shape": shape, "typestr": typestr, "data": (0x1000, False),
                                         "strides": strides, "version": 3, "stream": None}


def test_rasterize_checks_gpu_arrays_before_reading_them(vulkan):
    tri = np.array([[0, 1, 2]], np.int32)
    with pytest.raises(raster.Error, match="tensors on the GPU need a CUDA device"):
        raster.rasterize(_FakeGpuArray((3, 4)), tri, (8, 8), renderer=vulkan)
    with pytest.raises(raster.Error, match="must be float32"):
        raster.rasterize(_FakeGpuArray((3, 4), "<f8"), tri, (8, 8), renderer=vulkan)
    with pytest.raises(raster.Error, match=r"must have shape \(V, 4\)"):
        raster.rasterize(_FakeGpuArray((3, 3)), tri, (8, 8), renderer=vulkan)
    with pytest.raises(raster.Error, match="must be contiguous"):
        raster.rasterize(_FakeGpuArray((2, 3, 4), strides=(16, 96, 4)), tri, (8, 8), renderer=vulkan)
    with pytest.raises(raster.Error, match="has no copy to the host"):
        raster.rasterize(np.zeros((3, 4), np.float32), _FakeGpuArray((1, 3), "<i4"), (8, 8), renderer=vulkan)


def test_rasterize_takes_and_returns_gpu_tensors():
    """torch tensors on the GPU in, torch tensors on the GPU out, equal byte for byte to numpy in and
    out; the output shares memory with a DeviceArray of the same call's kind; a changed tri (in place) is
    read again. Needs CUDA and torch (the GPU machine's Python has both)."""
    r = renderer("cuda")
    torch = pytest.importorskip("torch")
    pos, tri = mesh(4, seed=9)
    tpos, ttri = torch.from_numpy(pos).cuda(), torch.from_numpy(tri).cuda()
    host = raster.rasterize(pos, tri, (40, 32), renderer=r)
    got = raster.rasterize(tpos, ttri, (40, 32), renderer=r)
    assert isinstance(got, torch.Tensor) and got.is_cuda and got.shape == (4, 40, 32, 4)
    np.testing.assert_array_equal(got.cpu().numpy(), host)
    empty = raster.rasterize(tpos, ttri[:0], (40, 32), renderer=r)
    assert isinstance(empty, torch.Tensor) and empty.is_cuda and not empty.any()
    as_host = raster.rasterize(tpos, ttri, (40, 32), renderer=r, on_device=False)
    assert isinstance(as_host, np.ndarray)
    np.testing.assert_array_equal(as_host, host)
    ttri[:, [1, 2]] = ttri[:, [2, 1]].clone()  # in place: the version counter moves
    np.testing.assert_array_equal(raster.rasterize(tpos, ttri, (40, 32), renderer=r).cpu().numpy(),
                                  raster.rasterize(pos, tri[:, [0, 2, 1]], (40, 32), renderer=r))
    # Written on another stream: the views wait for it.
    stream = torch.cuda.Stream()
    with torch.cuda.stream(stream):
        later = tpos * 1.0
        np.testing.assert_array_equal(raster.rasterize(later, ttri, (40, 32), renderer=r).cpu().numpy(),
                                      raster.rasterize(pos, tri[:, [0, 2, 1]], (40, 32), renderer=r))


def test_scenes_take_gpu_tensors_as_the_host_arrays_they_hold():
    """Scene.from_arrays and update_positions given torch tensors on the GPU make the scene the same
    arrays on the host make (the Scene is a host object: copied once), frames equal byte for byte.
    Needs CUDA and torch."""
    r = renderer("cuda")
    torch = pytest.importorskip("torch")
    pos, tri = mesh(2, seed=4)
    world = [np.ascontiguousarray(p[:, :3] / p[:, 3:]) for p in pos]
    kwargs = dict(camera="orbit:10,20,3.5", clusters="on")
    host = raster.Scene.from_arrays(world[0], tri, double_sided=True)
    gpu = raster.Scene.from_arrays(torch.from_numpy(world[0]).cuda(), torch.from_numpy(tri).cuda(),
                                   double_sided=True)
    for step in range(2):
        a, b = r.render(host, 64, 48, **kwargs), r.render(gpu, 64, 48, **kwargs)
        for name in ("color", "ids", "depth"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=f"{name}, step {step}")
        host.update_positions(world[1])
        gpu.update_positions(torch.from_numpy(world[1]).cuda())


def test_interpolate_refuses_arrays_split_between_host_and_gpu():
    with pytest.raises(raster.Error, match="all on the host or all on the GPU, not attr on the GPU, rast on "
                                           "the host, tri on the host"):
        raster.interpolate(_FakeGpuArray((3, 4)), np.zeros((1, 2, 2, 4), np.float32), [[0, 1, 2]])


def test_interpolate_on_the_gpu_equals_the_host():
    """attr, rast and tri as torch tensors on the GPU: a kernel interpolates, bit for bit the host's
    values (per-view and shared attributes), into a torch tensor on the GPU; bad ids and out-of-range
    vertices raise raster.Error. Needs CUDA and torch."""
    r = renderer("cuda")
    torch = pytest.importorskip("torch")
    pos, tri = mesh(3, seed=10)
    rast = raster.rasterize(pos, tri, (24, 40), renderer=r)
    rng = np.random.default_rng(10)
    for attr in (rng.standard_normal((3, pos.shape[1], 5)).astype(np.float32),
                 rng.standard_normal((pos.shape[1], 2)).astype(np.float32)):
        host = raster.interpolate(attr, rast, tri)
        got = raster.interpolate(torch.from_numpy(attr).cuda(), torch.from_numpy(rast).cuda(),
                                 torch.from_numpy(tri).cuda(), renderer=r)
        assert isinstance(got, torch.Tensor) and got.is_cuda and tuple(got.shape) == host.shape
        assert got.cpu().numpy().tobytes() == host.tobytes()
    trast, tattr = torch.from_numpy(rast).cuda(), torch.from_numpy(attr).cuda()
    bad_tri = torch.from_numpy(tri).cuda()
    drawn = int(rast[..., 3][rast[..., 3] > 0][0]) - 1  # a triangle some pixel shows
    bad_tri[drawn, 1] = pos.shape[1]
    with pytest.raises(raster.Error, match="indexes a vertex beyond attr's"):
        raster.interpolate(tattr, trast, bad_tri, renderer=r)
    trast[0, 3, 4, 3] = 1.5
    with pytest.raises(raster.Error, match=r"rast\[\.\.\., 3\] of pixel 124 \(flat\) is not a triangle id"):
        raster.interpolate(tattr, trast, torch.from_numpy(tri).cuda(), renderer=r)


def test_render_many_equals_a_render_per_camera(backend):
    """Renderer.render_many: frame k of its arrays equals render(cameras[k])'s images byte for byte
    (spec strings and a matrix pair), only the outputs asked for come back, and what it does not draw is
    refused."""
    r = renderer(backend)
    scene = raster.Scene.load("builtin:lowpoly")
    view = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -4], [0, 0, 0, 1]], np.float32)
    projection = np.array([[1.2, 0, 0, 0], [0, 1.6, 0, 0], [0, 0, -1.02, -0.2], [0, 0, -1, 0]], np.float32)
    cameras = ["orbit:0,20,3r", "orbit:120,-10,2r", (view, projection), "auto"]
    got = r.render_many(scene, 48, 36, cameras, msaa=2)
    assert got["color"].shape == (4, 36, 48, 4) and got["ids"].shape == got["depth"].shape == (4, 36, 48)
    for k, camera in enumerate(cameras):
        frame = r.render(scene, 48, 36, camera, msaa=2)
        for name in ("color", "ids", "depth"):
            np.testing.assert_array_equal(got[name][k], getattr(frame, name), err_msg=f"{name} of camera {k}")
    only = r.render_many(scene, 48, 36, cameras[:2], outputs=("ids",), msaa=2)
    assert set(only) == {"ids"}
    np.testing.assert_array_equal(only["ids"], got["ids"][:2])
    with pytest.raises(raster.Error, match="triangles"):
        r.render_many(scene, 8, 8, cameras, primitive_mode="lines")
    with pytest.raises(raster.Error, match="cameras must be a sequence"):
        r.render_many(scene, 8, 8, "auto")
    if backend == "cuda":
        on_gpu = r.render_many(scene, 48, 36, cameras, on_device=True, msaa=2)
        assert isinstance(on_gpu["ids"], raster.DeviceArray) and on_gpu["ids"].shape == (4, 36, 48)
        torch = pytest.importorskip("torch")
        for name in ("color", "ids", "depth"):
            np.testing.assert_array_equal(torch.from_dlpack(on_gpu[name]).cpu().numpy(), got[name])
