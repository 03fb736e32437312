// compare_backends - renders a glTF on the default device, renders it again on a second backend, and
// compares the two frames' triangle ids pixel by pixel: what a test suite of an application built on
// raster does. Only the installed header and library are used.
//
//   compare_backends SCENE [WIDTH HEIGHT]
//
// The second backend is the other compute backend when this machine has both (CUDA and Vulkan), else
// the Vulkan graphics pipeline (the conformant reference; on a CPU, Mesa lavapipe). Exit status 0 when
// every id agrees, 1 when some differ, 2 for an error.
#include <cstdio>
#include <cstdlib>
#include <string>

#include <raster/raster.h>

namespace {

int fail(const raster::Error& error)
{
    std::fprintf(stderr, "compare_backends: error: %s\n", error.message.c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc != 2 && argc != 4) {
        std::fprintf(stderr, "usage: compare_backends SCENE [WIDTH HEIGHT]\n");
        return 2;
    }
    auto scene = raster::Scene::load(argv[1]);
    if (!scene) return fail(scene.error());

    raster::Settings settings;
    if (argc == 4) {
        for (auto [name, text] :
             {std::pair<const char*, const char*>{"width", argv[2]}, {"height", argv[3]}}) {
            raster::Status set = settings.set(name, text);
            if (!set) return fail(set.error());
        }
    }
    const raster::Camera camera = raster::Camera::fromSpec("auto");

    // The default device: CUDA when there is an NVIDIA GPU, else Vulkan.
    auto first = raster::Device::open(raster::Backend::Auto);
    if (!first) return fail(first.error());
    const raster::Backend other =
        first->info().backend == raster::Backend::Cuda ? raster::Backend::Vulkan : raster::Backend::Cuda;
    auto second = raster::Device::open(other);
    if (!second) second = raster::Device::open(raster::Backend::VulkanGraphics);
    if (!second) return fail(second.error());

    auto a = raster::render(*first, *scene, camera, settings);
    if (!a) return fail(a.error());
    auto b = raster::render(*second, *scene, camera, settings);
    if (!b) return fail(b.error());

    size_t covered = 0, differ = 0;
    for (size_t i = 0; i < a->id.size(); ++i) {
        covered += a->id[i] != 0xffffffffu;
        differ += a->id[i] != b->id[i];
    }
    std::printf("%s: %zu triangles, %ux%u; %s (%s) against %s (%s): %zu covered pixels, %zu ids differ\n",
                argv[1], scene->triangleCount(), a->width, a->height, raster::backendName(a->device.backend),
                a->device.name.c_str(), raster::backendName(b->device.backend), b->device.name.c_str(),
                covered, differ);
    return differ == 0 && covered > 0 ? 0 : 1;
}
