// vulkan_device.cpp - the Vulkan backend of ComputeDevice.
//
// A VulkanContext (host/vulkan/vulkan_context.h) on a compute queue, one storage buffer per BUF_* binding
// plus a host-visible uniform buffer for RasterParams, the context's descriptor set shared by every
// stage, and one compute pipeline per stage built from the SPIR-V that CMake embeds
// (<builddir>/spirv/<stage>.spv.h). Every public call records one command buffer, submits it and
// waits on a fence.
//
// Buffer sizes: size() returns the byte count of the last resize(); the allocation behind it is
// that count rounded up to 16 bytes and is only replaced when a resize asks for more than it holds,
// so shrinking keeps the larger allocation. upload() and download() are checked against size().
#include <cstddef>
#include <vulkan/vulkan.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "render/compute_device.h"
#include "vulkan/vulkan_context.h"
#include "vulkan/pipeline_cache.h"
#include "vulkan/spirv_specialize.h"
#include "vulkan/vulkan_device_internal.h"
#include "vulkan/vulkan_present_source.h"

namespace sr {
namespace {

// The generated headers each define `const uint32_t kSpv_<module>[]`: stage_spirv.h includes the
// module of every stage of the table (common/shared/stages.h), the others are the raster methods'.
#include "stage_spirv.h"
#include "setup_lines_points.spv.h"
#include "setup_cpu.spv.h"
#include "setup_lines_points_cpu.spv.h"
#include "clusters_cpu.spv.h"
#include "raster_tiles_chunked.spv.h"
#include "ao_cpu.spv.h"
#include "ao_denoise_cpu.spv.h"
#include "ao_gbuffer_cpu.spv.h"
#include "aovs_cpu.spv.h"
#include "shade_cpu.spv.h"
#include "bin_count_fixed4.spv.h"
#include "bin_fill_fixed4.spv.h"
#include "raster_tiles_fixed4.spv.h"
#include "raster_tiles_chunked_fixed4.spv.h"
#include "setup_fixed4.spv.h"
#include "setup_lines_points_fixed4.spv.h"
#include "setup_cpu_fixed4.spv.h"
#include "setup_lines_points_cpu_fixed4.spv.h"
#include "clusters_fixed4.spv.h"
#include "clusters_cpu_fixed4.spv.h"
#include "bin_count_float.spv.h"
#include "bin_fill_float.spv.h"
#include "raster_tiles_float.spv.h"
#include "raster_tiles_chunked_float.spv.h"
#include "setup_float.spv.h"
#include "setup_lines_points_float.spv.h"
#include "setup_cpu_float.spv.h"
#include "setup_lines_points_cpu_float.spv.h"
#include "clusters_float.spv.h"
#include "clusters_cpu_float.spv.h"
#include "bin_count_scanline.spv.h"
#include "bin_fill_scanline.spv.h"
#include "raster_tiles_scanline.spv.h"
#include "raster_tiles_chunked_scanline.spv.h"
#include "setup_scanline.spv.h"
#include "setup_lines_points_scanline.spv.h"
#include "setup_cpu_scanline.spv.h"
#include "setup_lines_points_cpu_scanline.spv.h"
#include "clusters_scanline.spv.h"
#include "clusters_cpu_scanline.spv.h"

struct StageSpirv {
    const uint32_t* code;
    size_t bytes;
};
#define SR_SPIRV(array)     \
    StageSpirv              \
    {                       \
        array, sizeof array \
    }

// Indexed by STAGE_*: the modules of the stages no raster method changes (the others are in
// kMethodSpirv).
#define SR_STAGE_SPIRV(ID, name, function, threads, kind) SR_SPIRV(kSpv_##name),
const StageSpirv kStageSpirv[] = {SR_STAGE_TABLE(SR_STAGE_SPIRV)};
#undef SR_STAGE_SPIRV
static_assert(sizeof kStageSpirv / sizeof kStageSpirv[0] == STAGE_COUNT, "one module per stage");

// The modules of one raster method (RASTER_METHOD): setup without and with the line and point paths
// (SETUP_LINES_POINTS, for scenes that have lines or points), bin_count, bin_fill, raster_tiles
// resolving whole bins (GPUs) and in chunks (RASTER_TILES_CHUNKED, CPU devices), and setup's CPU builds
// (SR_CPU_BUILD: every big triangle stored as a record, which the chunked raster_tiles requires).
struct MethodSpirv {
    StageSpirv setup, setupLinesPoints, binCount, binFill, rasterTiles, rasterTilesChunked, setupCpu,
        setupLinesPointsCpu, clusters, clustersCpu;
};
// Indexed by RASTER_*.
const MethodSpirv kMethodSpirv[] = {
    {SR_SPIRV(kSpv_setup), SR_SPIRV(kSpv_setup_lines_points), SR_SPIRV(kSpv_bin_count),
     SR_SPIRV(kSpv_bin_fill), SR_SPIRV(kSpv_raster_tiles), SR_SPIRV(kSpv_raster_tiles_chunked),
     SR_SPIRV(kSpv_setup_cpu), SR_SPIRV(kSpv_setup_lines_points_cpu), SR_SPIRV(kSpv_clusters),
     SR_SPIRV(kSpv_clusters_cpu)},
    {SR_SPIRV(kSpv_setup_fixed4), SR_SPIRV(kSpv_setup_lines_points_fixed4), SR_SPIRV(kSpv_bin_count_fixed4),
     SR_SPIRV(kSpv_bin_fill_fixed4), SR_SPIRV(kSpv_raster_tiles_fixed4),
     SR_SPIRV(kSpv_raster_tiles_chunked_fixed4), SR_SPIRV(kSpv_setup_cpu_fixed4),
     SR_SPIRV(kSpv_setup_lines_points_cpu_fixed4), SR_SPIRV(kSpv_clusters_fixed4),
     SR_SPIRV(kSpv_clusters_cpu_fixed4)},
    {SR_SPIRV(kSpv_setup_float), SR_SPIRV(kSpv_setup_lines_points_float), SR_SPIRV(kSpv_bin_count_float),
     SR_SPIRV(kSpv_bin_fill_float), SR_SPIRV(kSpv_raster_tiles_float),
     SR_SPIRV(kSpv_raster_tiles_chunked_float), SR_SPIRV(kSpv_setup_cpu_float),
     SR_SPIRV(kSpv_setup_lines_points_cpu_float), SR_SPIRV(kSpv_clusters_float),
     SR_SPIRV(kSpv_clusters_cpu_float)},
    {SR_SPIRV(kSpv_setup_scanline), SR_SPIRV(kSpv_setup_lines_points_scanline),
     SR_SPIRV(kSpv_bin_count_scanline), SR_SPIRV(kSpv_bin_fill_scanline),
     SR_SPIRV(kSpv_raster_tiles_scanline), SR_SPIRV(kSpv_raster_tiles_chunked_scanline),
     SR_SPIRV(kSpv_setup_cpu_scanline), SR_SPIRV(kSpv_setup_lines_points_cpu_scanline),
     SR_SPIRV(kSpv_clusters_scanline), SR_SPIRV(kSpv_clusters_cpu_scanline)},
};
static_assert(sizeof kMethodSpirv / sizeof kMethodSpirv[0] == RASTER_METHOD_COUNT, "modules per method");
#undef SR_SPIRV

constexpr VkBufferUsageFlags kStorageUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// The texel views of CPU devices (VIEW_*, common/raster_shared.h), indexed by VIEW_* - BUF_COUNT: the
// buffer each shows and its texel format.
struct TexelView {
    uint32_t buffer;
    VkFormat format;
    VkDeviceSize texelBytes;
};
constexpr TexelView kTexelViews[VIEW_COUNT] = {
    {BUF_SETUP_TRIS, VK_FORMAT_R32G32B32A32_UINT, 16}, {BUF_BIN_ENTRIES, VK_FORMAT_R32_UINT, 4},
    {BUF_VISIBILITY, VK_FORMAT_R32G32_UINT, 8},        {BUF_INDICES, VK_FORMAT_R32_UINT, 4},
    {BUF_POSITIONS, VK_FORMAT_R32G32B32A32_UINT, 16},  {BUF_NORMALS, VK_FORMAT_R32G32B32A32_UINT, 16},
    {BUF_COLORS, VK_FORMAT_R32G32B32A32_UINT, 16},     {BUF_TEXCOORDS, VK_FORMAT_R32G32B32A32_UINT, 16},
    {BUF_TRI_MATERIALS, VK_FORMAT_R32_UINT, 4},        {BUF_MATERIALS, VK_FORMAT_R32G32B32A32_UINT, 16},
    {BUF_TEXTURES, VK_FORMAT_R32G32B32A32_UINT, 16},   {BUF_TEXELS, VK_FORMAT_R32_UINT, 4},
    {BUF_SRGB_TABLE, VK_FORMAT_R32_UINT, 4},           {BUF_AO, VK_FORMAT_R32_UINT, 4}};
static_assert(VIEW_SETUP_TRIS == BUF_COUNT && VIEW_AO == BUF_COUNT + VIEW_COUNT - 1, "kTexelViews order");
static_assert(sizeof(GpuMaterial) == 96 && sizeof(GpuTexture) == 32, "texels per record in buffers.glsl");

// Everything a later submission may do with a buffer: compute stages read and write it, transfers
// copy from and into it.
constexpr VkPipelineStageFlags kBufferUserStages =
    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
constexpr VkAccessFlags kBufferUserAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                            VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;

class VulkanDevice final : public ComputeDevice {
public:
    VulkanDevice() = default;
    VulkanDevice(const VulkanDevice&) = delete;
    VulkanDevice& operator=(const VulkanDevice&) = delete;
    ~VulkanDevice() override;

    // Creates everything; on failure the destructor releases whatever was created.
    Status init(int index, const PresentTarget* present);
    VulkanContext& context() { return context_; }
    VkBuffer buffer(uint32_t index) const { return buffers_[index].buffer; }
    Status injectValidationError(const char* message) { return context_.injectValidationError(message); }

    const DeviceInfo& info() const override { return info_; }
    Status resize(uint32_t buffer, size_t bytes) override
    {
        return checked([&] { return resizeBuffer(buffer, bytes); });
    }
    size_t size(uint32_t buffer) const override
    {
        return buffer > BUF_PARAMS && buffer < BUF_COUNT ? sizes_[buffer] : 0;
    }
    Status upload(uint32_t buffer, const void* data, size_t bytes) override
    {
        return checked([&] { return uploadBuffer(buffer, data, bytes); });
    }
    Status download(uint32_t buffer, void* data, size_t bytes, size_t offset = 0) override
    {
        return checked([&] { return downloadBuffer(buffer, data, bytes, offset); });
    }
    Status run(const RasterParams& params, const std::vector<Dispatch>& dispatches,
               std::vector<double>& gpuMs) override
    {
        return checked([&] { return runDispatches(params, dispatches, gpuMs); });
    }
    size_t allocatedBytes() const override { return context_.allocatedBytes(); }
    size_t peakAllocatedBytes() const override { return context_.peakAllocatedBytes(); }

private:
    // Runs `body` unless validation already failed, and fails it when validation complained during
    // it: a validation error names the real cause of whatever the body's own error would be.
    template <typename Body>
    Status checked(Body&& body)
    {
        SR_TRY(context_.validationStatus());
        Status result = body();
        SR_TRY(context_.validationStatus());
        return result;
    }

    // One build of a stage: its specialization constants SPEC_MATERIALS, SPEC_SAMPLES, SPEC_RESOLVE, and
    // its module (kMethodSpirv: the raster method's, for setup with or without the line and point paths).
    struct Build {
        bool materials = false;
        uint32_t samples = 1;
        bool resolve = false;
        bool linesPoints = false;
        uint32_t method = RASTER_FIXED8;  // RASTER_*: the modules of setup, bin_count, bin_fill, raster_tiles
        uint32_t shadeMode = 0;           // shade on a CPU device: SPEC_SHADE_MODE, the frame's SHADING_*
        uint32_t shadeUses = 0;           // SPEC_SHADE_USES, its SHADE_USES_* (0 elsewhere)
        uint32_t shadeSsaa = 0;           // and SPEC_SHADE_SSAA, its SSAA factor
        bool countHits = false;           // raster_tiles on a CPU device: SPEC_COUNT_HITS
        bool idsDepthOnly = false;        // aovs on a CPU device without surfaces: kSpv_aovs_cpu
        bool operator<(const Build& o) const
        {
            return std::tie(materials, samples, resolve, linesPoints, method, shadeMode, shadeUses, shadeSsaa,
                            countHits, idsDepthOnly) <
                   std::tie(o.materials, o.samples, o.resolve, o.linesPoints, o.method, o.shadeMode,
                            o.shadeUses, o.shadeSsaa, o.countHits, o.idsDepthOnly);
        }
    };
    // SHADE_USES_* of a frame with `params` on this device's buffers.
    uint32_t shadeUses(const RasterParams& params) const;
    Status createPipeline(uint32_t stage, const Build& build, VkPipeline& pipeline);
    // Where the pipeline dispatch `d` runs in a frame with `params` is kept, and its build; the slot is
    // null until a frame first asks for it (createPipelines, through pipelineCache_): a run compiles only
    // the stages and builds its frames use.
    Result<VkPipeline*> pipelineSlot(const Dispatch& d, const RasterParams& params, Build& build);
    struct PipelineToMake {
        uint32_t stage;
        Build build;
        VkPipeline* slot;
    };
    Status createPipelines(const std::vector<PipelineToMake>& wanted);
    // Writes the pipeline cache after a frame that created pipelines. A failure is one warning, and the
    // cache is not saved again by this device: it only costs the next run's start-up time.
    void savePipelineCache();
    Status ensureBindings();
    Status checkTransfer(const char* what, uint32_t buffer, size_t bytes) const;
    Status resizeBuffer(uint32_t buffer, size_t bytes);
    Status uploadBuffer(uint32_t buffer, const void* data, size_t bytes);
    Status downloadBuffer(uint32_t buffer, void* data, size_t bytes, size_t offset);
    Status runDispatches(const RasterParams& params, const std::vector<Dispatch>& dispatches,
                         std::vector<double>& gpuMs);
    // Records stage clear as buffer fills (CPU devices): what compute_glsl/clear.comp writes.
    void fillForClear(VkCommandBuffer cmd, const RasterParams& params) const;

    // Declared first, so destroyed last: everything below is created through it.
    VulkanContext context_;
    DeviceInfo info_;
    PipelineCache pipelineCache_;              // destroyed before the context's device
    std::atomic<bool> pipelinesAdded_{false};  // pipelines were created since the cache was last saved
    std::mutex modulesMutex_;                  // pipelineCache_'s modules, for createPipelines' threads
    // Modules specialized before the driver sees them: on CPU devices, unless RASTER_SPECIALIZE=off.
    bool specialize_ = false;
    bool pipelineCacheSaves_ = true;  // false after a failed save
    VkPipeline pipelines_[STAGE_COUNT] = {};
    // setup and raster_tiles built with the alpha test of MASK materials (SPEC_MATERIALS), bound for
    // dispatches that ask for it (Dispatch::alphaTest); pipelines_ has them without it. Null for the
    // other stages, and for these until a frame asks for them.
    VkPipeline materialPipelines_[STAGE_COUNT] = {};
    // setup, raster_tiles and shade for MSAA or SSAA, the line and point build of setup, and the builds of
    // the other raster methods, by stage and build; made when a frame first asks for them.
    std::map<std::pair<uint32_t, Build>, VkPipeline> sampledPipelines_;
    // Usage of buffer i: storage and transfers, and on a CPU device a texel view's buffer also that.
    VkBufferUsageFlags usage(uint32_t buffer) const;
    // Replaces the texel views (CPU devices) by views of the current buffers.
    Status createTexelViews();
    void destroyTexelViews();

    GpuBuffer buffers_[BUF_COUNT];         // BUF_PARAMS is the uniform buffer, the rest storage buffers
    VkBufferView views_[VIEW_COUNT] = {};  // CPU devices: kTexelViews of buffers_, else null
    size_t sizes_[BUF_COUNT] = {};         // logical sizes, as resize() was last asked
    bool descriptorsDirty_ = true;         // a buffer was replaced since the descriptor set was written
    // SHADE_USES_BASE_TEXTURES and SHADE_USES_EMISSIVE_TEXTURES of the materials last uploaded, and the
    // SHADE_USES_*_FILTER and SHADE_USES_MIP_BLEND bits of the textures' samplers.
    uint32_t materialTextureUses_ = 0;
    uint32_t samplerUses_ = 0;
};

VulkanDevice::~VulkanDevice()
{
    if (context_.device() == VK_NULL_HANDLE) return;
    context_.waitIdle();
    destroyTexelViews();
    for (GpuBuffer& b : buffers_) context_.destroyBuffer(b);
    for (VkPipeline pipeline : pipelines_) vkDestroyPipeline(context_.device(), pipeline, nullptr);
    for (VkPipeline pipeline : materialPipelines_) vkDestroyPipeline(context_.device(), pipeline, nullptr);
    for (auto& [variant, pipeline] : sampledPipelines_)
        vkDestroyPipeline(context_.device(), pipeline, nullptr);
}

Status VulkanDevice::init(int index, const PresentTarget* present)
{
    SR_TRY(context_.init(index, QueueKind::Compute, present));
    info_ = context_.deviceInfo("vulkan");
    SR_TRY(pipelineCache_.open(context_.device(), pipelineCacheFile(context_.properties())));
    // RASTER_SPECIALIZE=off hands a CPU device the modules as built, as a GPU gets them: the same images
    // (tests/spirv_specialize_test.cpp), created slower; a way to rule the optimizer out.
    const char* specialize = std::getenv("RASTER_SPECIALIZE");
    if (specialize && std::string(specialize) != "on" && std::string(specialize) != "off")
        return makeError(ExitCode::Usage, "RASTER_SPECIALIZE is {}; it takes on or off",
                         quotedInput(specialize));
    specialize_ = info_.isCpu && !(specialize && std::string(specialize) == "off");
    // Host-visible so that run() writes the parameters directly; device-local where the device
    // offers such memory (resizable BAR), which makes the reads from every stage cheaper.
    SR_TRY(context_.allocateBuffer(
        buffers_[BUF_PARAMS], roundUp(sizeof(RasterParams), kMinBufferBytes),
        VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
        {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
             VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT}));
    return context_.validationStatus();
}

Status VulkanDevice::createPipeline(uint32_t stage, const Build& build, VkPipeline& pipeline)
{
    // Specialization constant 0, the invocations of a raster_tiles group: one per tile pixel on a GPU;
    // on a CPU device (lavapipe), where each invocation of a group that synchronizes runs as a
    // coroutine, one SIMD-wide bundle that walks several pixels each (compute_glsl/raster_tiles.comp).
    // Specialization constant SPEC_MATERIALS of setup, clusters and raster_tiles: whether the alpha test of
    // MASK materials is compiled in. Each is built both ways, so that scenes without MASK triangles run code
    // without the test's surface, material and texture lookups (fewer registers on a GPU; on a CPU, where
    // both sides of a per-pixel branch run, none of the test's work). SPEC_SAMPLES of setup, raster_tiles
    // and shade: the sample count, which sizes each invocation's array of keys or ids. SPEC_RESOLVE of
    // shade: whether output pixels have several samples. The one-sample builds hold none of the
    // anti-aliasing loops, which a CPU device would otherwise run masked at every pixel. setup's line and
    // point paths are a second module (kSetupLinesPointsSpirv): NVIDIA's compiler slowed the triangle
    // path by 35-95% with the point code in the same module (compute_glsl/setup.comp).
    // On a CPU device shade is a second module (kSpv_shade_cpu) with SPEC_SHADE_MODE, SPEC_SHADE_USES and
    // SPEC_SHADE_SSAA: the frame's shading mode, scene features and SSAA factor, so that it holds only the
    // code the frame can reach and its resolve loops unroll. setup's CPU build stores every big triangle
    // as a record (MethodSpirv), which raster_tiles' CPU build reads through a texel view; that build
    // takes SPEC_COUNT_HITS, so that a frame without the hit count holds none of its stores.
    struct Constants {
        uint32_t rasterLanes;
        VkBool32 materials;
        uint32_t samples;
        VkBool32 resolve;
        uint32_t shadeMode;
        uint32_t shadeUses;
        uint32_t shadeSsaa;
        VkBool32 countHits;
    } constants = {info_.isCpu ? uint32_t(MIN_RASTER_LANES) : uint32_t(TILE_SIZE * TILE_SIZE),
                   build.materials ? VK_TRUE : VK_FALSE,
                   build.samples,
                   build.resolve ? VK_TRUE : VK_FALSE,
                   build.shadeMode,
                   build.shadeUses,
                   build.shadeSsaa,
                   build.countHits ? VK_TRUE : VK_FALSE};
    const VkSpecializationMapEntry entries[8] = {
        {0, offsetof(Constants, rasterLanes), sizeof(uint32_t)},
        {SPEC_MATERIALS, offsetof(Constants, materials), sizeof(VkBool32)},
        {SPEC_SAMPLES, offsetof(Constants, samples), sizeof(uint32_t)},
        {SPEC_RESOLVE, offsetof(Constants, resolve), sizeof(VkBool32)},
        {SPEC_SHADE_MODE, offsetof(Constants, shadeMode), sizeof(uint32_t)},
        {SPEC_SHADE_USES, offsetof(Constants, shadeUses), sizeof(uint32_t)},
        {SPEC_SHADE_SSAA, offsetof(Constants, shadeSsaa), sizeof(uint32_t)},
        {SPEC_COUNT_HITS, offsetof(Constants, countHits), sizeof(VkBool32)}};
    bool variants = stage == STAGE_SETUP || stage == STAGE_CLUSTERS || stage == STAGE_RASTER_TILES ||
                    stage == STAGE_SHADE;
    const MethodSpirv& m = kMethodSpirv[build.method];
    StageSpirv spirv = kStageSpirv[stage];
    if (stage == STAGE_SETUP && info_.isCpu) spirv = build.linesPoints ? m.setupLinesPointsCpu : m.setupCpu;
    if (stage == STAGE_SETUP && !info_.isCpu) spirv = build.linesPoints ? m.setupLinesPoints : m.setup;
    if (stage == STAGE_CLUSTERS) spirv = info_.isCpu ? m.clustersCpu : m.clusters;
    if (stage == STAGE_BIN_COUNT) spirv = m.binCount;
    if (stage == STAGE_BIN_FILL) spirv = m.binFill;
    if (stage == STAGE_RASTER_TILES) spirv = info_.isCpu ? m.rasterTilesChunked : m.rasterTiles;
    if (stage == STAGE_SHADE && info_.isCpu) spirv = StageSpirv{kSpv_shade_cpu, sizeof kSpv_shade_cpu};
    // The AO stages' CPU builds read through the texel views (AO_CPU, compute_glsl/buffers.glsl).
    if (stage == STAGE_AO_GBUFFER && info_.isCpu)
        spirv = StageSpirv{kSpv_ao_gbuffer_cpu, sizeof kSpv_ao_gbuffer_cpu};
    if (stage == STAGE_AO && info_.isCpu) spirv = StageSpirv{kSpv_ao_cpu, sizeof kSpv_ao_cpu};
    if (stage == STAGE_AO_DENOISE && info_.isCpu)
        spirv = StageSpirv{kSpv_ao_denoise_cpu, sizeof kSpv_ao_denoise_cpu};
    // aovs' CPU build writes ids and depth alone (compute_glsl/aovs.comp).
    if (stage == STAGE_AOVS && build.idsDepthOnly) spirv = StageSpirv{kSpv_aovs_cpu, sizeof kSpv_aovs_cpu};
    // A CPU device gets the module specialized to the constants first (spirv_specialize.h): the same
    // pipeline, which lavapipe translates several times faster. Should the optimizer refuse a module, the
    // original does the same work, slower to create.
    std::vector<uint32_t> specialized;
    if (specialize_) {
        std::vector<SpecValue> values;
        if (variants)
            for (const VkSpecializationMapEntry& e : entries) {
                uint32_t bits;
                std::memcpy(&bits, reinterpret_cast<const unsigned char*>(&constants) + e.offset,
                            sizeof bits);
                values.push_back({e.constantID, bits});
            }
        // Specialized once per module and constants: the pipeline cache keeps the result for later runs.
        // Pipelines are created on several threads (createPipelines); each takes a copy of its module.
        const std::string key = specializationKey(spirv.code, spirv.bytes, values);
        {
            std::lock_guard<std::mutex> lock(modulesMutex_);
            if (const std::vector<uint32_t>* cached = pipelineCache_.module(key)) specialized = *cached;
        }
        if (specialized.empty()) {
            Result<std::vector<uint32_t>> s = specializeModule(spirv.code, spirv.bytes, values);
            if (s.ok()) {
                specialized = std::move(*s);
                std::lock_guard<std::mutex> lock(modulesMutex_);
                pipelineCache_.addModule(key, specialized);
            } else {
                fmt::print(stderr, "warning: {}\n", s.error().message);
            }
        }
        if (!specialized.empty())
            spirv = StageSpirv{specialized.data(), specialized.size() * sizeof(uint32_t)};
    }
    Result<VkShaderModule> module = context_.createShaderModule(spirv.code, spirv.bytes);
    if (!module.ok()) return module.error();
    VkSpecializationInfo specialization{};
    specialization.mapEntryCount = 8;  // a shader ignores the constants it does not declare
    specialization.pMapEntries = entries;
    specialization.dataSize = sizeof(Constants);
    specialization.pData = &constants;

    VkComputePipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    info.flags = VK_PIPELINE_CREATE_DISPATCH_BASE_BIT;  // large dispatches are split, see runDispatches
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = *module;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = variants ? &specialization : nullptr;
    info.layout = context_.pipelineLayout();
    VkResult result =
        vkCreateComputePipelines(context_.device(), pipelineCache_.handle(), 1, &info, nullptr, &pipeline);
    // The pipeline keeps what it needs of the module.
    vkDestroyShaderModule(context_.device(), *module, nullptr);
    if (result != VK_SUCCESS)
        return vkError(result, fmt::format("vkCreateComputePipelines (stage {})", stageName(stage)), __FILE__,
                       __LINE__);
    pipelinesAdded_ = true;
    return okStatus();
}

void VulkanDevice::savePipelineCache()
{
    if (!pipelinesAdded_ || !pipelineCacheSaves_) return;
    pipelinesAdded_ = false;
    Status saved = pipelineCache_.save();
    if (saved) return;
    pipelineCacheSaves_ = false;
    fmt::print(stderr, "warning: pipeline cache not saved: {}\n", saved.error().message);
}

Result<VkPipeline*> VulkanDevice::pipelineSlot(const Dispatch& d, const RasterParams& params, Build& build)
{
    build = Build{};
    build.materials =
        d.alphaTest && (d.stage == STAGE_SETUP || d.stage == STAGE_CLUSTERS || d.stage == STAGE_RASTER_TILES);
    if (d.stage == STAGE_SETUP || d.stage == STAGE_CLUSTERS || d.stage == STAGE_RASTER_TILES ||
        d.stage == STAGE_SHADE)
        build.samples = params.sampleCount;
    build.resolve = d.stage == STAGE_SHADE && (params.sampleCount > 1 || params.ssaa > 1);
    build.linesPoints = d.stage == STAGE_SETUP && params.lineCount + params.pointCount > 0;
    build.method = methodStage(d.stage) ? d.rasterMethod : uint32_t(RASTER_FIXED8);
    build.countHits =
        d.stage == STAGE_RASTER_TILES && info_.isCpu && (params.debugFlags & DEBUG_COUNT_HITS) != 0;
    build.idsDepthOnly =
        d.stage == STAGE_AOVS && info_.isCpu && (params.aovOutputs & (AOV_OUT_SURFACE | AOV_OUT_RAST)) == 0u;
    if (d.stage == STAGE_SHADE && info_.isCpu) {
        build.shadeMode = params.shadingMode;
        build.shadeUses = shadeUses(params);
        build.shadeSsaa = params.ssaa;
    }
    if (build.method >= RASTER_METHOD_COUNT)
        return makeError(ExitCode::Usage, "unknown raster method {}", build.method);
    if (build.samples == 1 && !build.resolve && !build.linesPoints && build.method == RASTER_FIXED8 &&
        build.shadeUses == 0 && build.shadeMode == 0 && build.shadeSsaa == 0 && !build.countHits &&
        !build.idsDepthOnly)
        return build.materials ? &materialPipelines_[d.stage] : &pipelines_[d.stage];
    return &sampledPipelines_[{d.stage, build}];
}

Status VulkanDevice::createPipelines(const std::vector<PipelineToMake>& wanted)
{
    // One at a time when there is one; else the CPU's cores each take the next pipeline not yet taken.
    // Drivers create pipelines concurrently (the cache is internally synchronized), and on a CPU device,
    // where creating a frame's pipelines is most of a short run, that divides the wait by the cores.
    std::vector<Status> made(wanted.size(), okStatus());
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t i = next++; i < wanted.size(); i = next++)
            made[i] = createPipeline(wanted[i].stage, wanted[i].build, *wanted[i].slot);
    };
    const size_t workers = std::min<size_t>(wanted.size(), std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> helpers;
    for (size_t w = 1; w < workers; ++w) helpers.emplace_back(work);
    work();
    for (std::thread& t : helpers) t.join();
    for (Status& m : made) SR_TRY(m);
    return okStatus();
}

Status VulkanDevice::ensureBindings()
{
    for (uint32_t i = BUF_PARAMS + 1; i < BUF_COUNT; ++i) {
        GpuBuffer& b = buffers_[i];
        if (b.capacity > 0) continue;
        // The descriptor set names every binding, and each must be a valid buffer, whether or not
        // the stages of this run touch it.
        context_.destroyBuffer(b);
        descriptorsDirty_ = true;
        SR_TRY(context_.allocateBuffer(b, i == BUF_SRGB_TABLE ? kSrgbTableBytes : kMinBufferBytes, usage(i),
                                       {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    }
    if (!descriptorsDirty_) return okStatus();
    VkBuffer handles[BUF_COUNT];
    for (uint32_t i = 0; i < BUF_COUNT; ++i) handles[i] = buffers_[i].buffer;
    // No submitted work uses the set any more (every call waits), so it and the views can be replaced.
    if (context_.texelViews()) {
        SR_TRY(createTexelViews());
        context_.writeDescriptorSet(handles, views_);
    } else {
        context_.writeDescriptorSet(handles);
    }
    descriptorsDirty_ = false;
    return okStatus();
}

VkBufferUsageFlags VulkanDevice::usage(uint32_t buffer) const
{
    VkBufferUsageFlags flags = kStorageUsage;
    if (uniformBinding(buffer)) flags |= VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
    if (context_.texelViews())
        for (const TexelView& v : kTexelViews)
            if (v.buffer == buffer) flags |= VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
    return flags;
}

Status VulkanDevice::createTexelViews()
{
    destroyTexelViews();
    const VkDeviceSize maxTexels = context_.properties().limits.maxTexelBufferElements;
    for (uint32_t k = 0; k < VIEW_COUNT; ++k) {
        const TexelView& v = kTexelViews[k];
        // The whole buffer, in whole texels (capacities are multiples of kMinBufferBytes, 16), up to the
        // device's limit; a fetch beyond a view's range reads zero.
        VkDeviceSize texels = std::min(buffers_[v.buffer].capacity / v.texelBytes, maxTexels);
        VkBufferViewCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
        info.buffer = buffers_[v.buffer].buffer;
        info.format = v.format;
        info.offset = 0;
        info.range = texels * v.texelBytes;
        SR_VK_CHECK(vkCreateBufferView(context_.device(), &info, nullptr, &views_[k]));
    }
    return okStatus();
}

void VulkanDevice::destroyTexelViews()
{
    for (VkBufferView& view : views_) {
        if (view != VK_NULL_HANDLE) vkDestroyBufferView(context_.device(), view, nullptr);
        view = VK_NULL_HANDLE;
    }
}

Status VulkanDevice::checkTransfer(const char* what, uint32_t buffer, size_t bytes) const
{
    if (buffer <= BUF_PARAMS || buffer >= BUF_COUNT)
        return makeError(ExitCode::Runtime, "vulkan: {} of invalid buffer index {}", what, buffer);
    if (bytes > sizes_[buffer])
        return makeError(ExitCode::Runtime, "vulkan: {} of {} bytes but buffer {} holds {} bytes", what,
                         bytes, buffer, sizes_[buffer]);
    return okStatus();
}

Status VulkanDevice::resizeBuffer(uint32_t buffer, size_t bytes)
{
    if (buffer <= BUF_PARAMS || buffer >= BUF_COUNT)
        return makeError(ExitCode::Runtime, "vulkan: resize of invalid buffer index {}", buffer);
    // A storage descriptor covers the whole buffer, so the buffer may not exceed the device's
    // range.
    const VkDeviceSize maxStorageBytes = context_.maxStorageBytes();
    if (bytes > maxStorageBytes ||
        roundUp(std::max<VkDeviceSize>(bytes, kMinBufferBytes), kMinBufferBytes) > maxStorageBytes)
        return makeError(ExitCode::Runtime,
                         "vulkan: buffer {} needs {} bytes, more than the device allows per storage "
                         "buffer ({} bytes)",
                         buffer, bytes, maxStorageBytes);
    const VkDeviceSize capacity = roundUp(std::max<VkDeviceSize>(bytes, kMinBufferBytes), kMinBufferBytes);
    GpuBuffer& b = buffers_[buffer];
    if (b.capacity >= capacity) {
        sizes_[buffer] = bytes;
        return okStatus();
    }
    // Free first so that the old and new allocations never coexist; the contents are undefined
    // anyway. The texel views go with it and are made again with the descriptor set.
    destroyTexelViews();
    context_.destroyBuffer(b);
    sizes_[buffer] = 0;
    descriptorsDirty_ = true;
    SR_TRY(context_.allocateBuffer(b, capacity, usage(buffer), {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    sizes_[buffer] = bytes;
    return okStatus();
}

uint32_t VulkanDevice::shadeUses(const RasterParams& params) const
{
    uint32_t uses = 0;
    if (params.materialCount > 0) uses |= SHADE_USES_MATERIALS;
    if (params.materialCount > 0 && params.textureCount > 0) {
        uses |= materialTextureUses_;
        // The --texture-filter override replaces every sampler's filters (textureSelect).
        switch (params.textureFilter) {
        case TEXTURE_FILTER_NEAREST: uses |= SHADE_USES_NEAREST_FILTER; break;
        case TEXTURE_FILTER_BILINEAR: uses |= SHADE_USES_LINEAR_FILTER; break;
        case TEXTURE_FILTER_TRILINEAR: uses |= SHADE_USES_LINEAR_FILTER | SHADE_USES_MIP_BLEND; break;
        default: uses |= samplerUses_;
        }
    }
    if (params.hasColors != 0) uses |= SHADE_USES_COLORS;
    if (params.lineCount + params.pointCount > 0) uses |= SHADE_USES_LINES_POINTS;
    if (params.uvInterpolation == UV_AFFINE) uses |= SHADE_USES_AFFINE_UV;
    return uses;
}

Status VulkanDevice::uploadBuffer(uint32_t buffer, const void* data, size_t bytes)
{
    SR_TRY(checkTransfer("upload", buffer, bytes));
    if (buffer == BUF_MATERIALS) {
        // Which texture lookups shade's CPU build needs (shadeUses): an index at or beyond the frame's
        // textureCount is no texture, so any index counts here.
        materialTextureUses_ = 0;
        const auto* materials = static_cast<const GpuMaterial*>(data);
        for (size_t k = 0; k < bytes / sizeof(GpuMaterial); ++k) {
            if (materials[k].baseColorTexture != NO_TEXTURE) materialTextureUses_ |= SHADE_USES_BASE_TEXTURES;
            if (materials[k].emissiveTexture != NO_TEXTURE)
                materialTextureUses_ |= SHADE_USES_EMISSIVE_TEXTURES;
        }
    }
    if (buffer == BUF_TEXTURES) {
        samplerUses_ = 0;
        const auto* textures = static_cast<const GpuTexture*>(data);
        for (size_t k = 0; k < bytes / sizeof(GpuTexture); ++k) {
            uint32_t mag = textures[k].filters & 255u, min = (textures[k].filters >> 8) & 255u;
            for (uint32_t filter : {mag, min})
                samplerUses_ |=
                    filter == FILTER_NEAREST ? SHADE_USES_NEAREST_FILTER : SHADE_USES_LINEAR_FILTER;
            if (((textures[k].filters >> 16) & 255u) == MIPMAP_LINEAR) samplerUses_ |= SHADE_USES_MIP_BLEND;
        }
    }
    if (bytes == 0) return okStatus();
    // The next run's stages and transfers see the data.
    return context_.upload(buffers_[buffer].buffer, data, bytes, kBufferUserStages, kBufferUserAccess);
}

Status VulkanDevice::downloadBuffer(uint32_t buffer, void* data, size_t bytes, size_t offset)
{
    if (offset > SIZE_MAX - bytes)
        return makeError(ExitCode::Runtime, "vulkan: download of {} bytes at offset {}", bytes, offset);
    SR_TRY(checkTransfer("download", buffer, offset + bytes));
    if (bytes == 0) return okStatus();
    return context_.download(buffers_[buffer].buffer, data, bytes, offset);
}

void VulkanDevice::fillForClear(VkCommandBuffer cmd, const RasterParams& params) const
{
    // Fills the first `bytes` of `buffer` (at most its logical size) with the 32-bit word `word`.
    auto fill = [&](uint32_t buffer, size_t bytes, uint32_t word) {
        bytes = std::min(bytes, sizes_[buffer]) & ~size_t(3);
        if (bytes > 0) vkCmdFillBuffer(cmd, buffers_[buffer].buffer, 0, bytes, word);
    };
    size_t samples = size_t(params.samplePlane) * params.sampleCount;
    fill(BUF_COUNTERS, COUNTER_WORDS * sizeof(uint32_t), 0u);
    fill(BUF_TILE_BINS, size_t(params.tilesX) * params.tilesY * sizeof(uint32_t), 0u);
    fill(BUF_VISIBILITY, samples * sizeof(uint64_t), 0xFFFFFFFFu);
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) fill(BUF_HIT_COUNT, samples * sizeof(uint32_t), 0u);
}

Status VulkanDevice::runDispatches(const RasterParams& params, const std::vector<Dispatch>& dispatches,
                                   std::vector<double>& gpuMs)
{
    gpuMs.clear();
    const uint32_t maxGroups = context_.properties().limits.maxComputeWorkGroupCount[0];
    for (const Dispatch& d : dispatches) {
        if (d.stage >= STAGE_COUNT)
            return makeError(ExitCode::Runtime, "vulkan: dispatch of unknown stage {}", d.stage);
        if (d.groups > MAX_DISPATCH_GROUPS)
            return makeError(ExitCode::Runtime,
                             "vulkan: stage {} needs {} groups, more than the {} of one dispatch",
                             stageName(d.stage), d.groups, MAX_DISPATCH_GROUPS);
    }
    if (dispatches.empty()) return okStatus();
    // The frame's pipelines, those it is the first to use created now, together. A dispatch of no groups
    // (a stage the frame skips) and a CPU device's clear (buffer fills) bind none.
    std::vector<VkPipeline*> slots(dispatches.size(), nullptr);
    std::vector<PipelineToMake> wanted;
    for (size_t i = 0; i < dispatches.size(); ++i) {
        if (dispatches[i].groups == 0 || (dispatches[i].stage == STAGE_CLEAR && info_.isCpu)) continue;
        Build build;
        Result<VkPipeline*> slot = pipelineSlot(dispatches[i], params, build);
        if (!slot.ok()) return slot.error();
        slots[i] = *slot;
        bool listed = std::any_of(wanted.begin(), wanted.end(),
                                  [&](const PipelineToMake& w) { return w.slot == *slot; });
        if (**slot == VK_NULL_HANDLE && !listed) wanted.push_back({dispatches[i].stage, build, *slot});
    }
    SR_TRY(createPipelines(wanted));
    std::vector<VkPipeline> bound(dispatches.size(), VK_NULL_HANDLE);
    for (size_t i = 0; i < dispatches.size(); ++i)
        if (slots[i]) bound[i] = *slots[i];

    // A dispatch of no groups (a stage the frame skips) records nothing, no timestamps and no barrier, and
    // its time is 0: with them, each such stage measured 0.6-0.7 us of nothing on the H200, summed into
    // the frame's time (docs/benchmark.md, "Sixth pass").
    uint32_t pairs = 0;
    for (const Dispatch& d : dispatches) pairs += d.groups > 0 ? 1u : 0u;
    const uint32_t queries = 2 * std::max(pairs, 1u);  // a pool of at least one pair
    SR_TRY(context_.ensureQueryPool(queries));
    SR_TRY(ensureBindings());
    // Nothing submitted earlier still reads the uniform buffer, so it is overwritten in place.
    std::memcpy(buffers_[BUF_PARAMS].mapped, &params, sizeof params);

    SR_TRY(context_.beginCommands());
    VkCommandBuffer cmd = context_.commandBuffer();
    VkQueryPool queryPool = context_.queryPool();
    VkDescriptorSet set = context_.descriptorSet();
    vkCmdResetQueryPool(cmd, queryPool, 0, queries);
    // All pipelines share one layout, so the set stays bound across the pipeline switches below.
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, context_.pipelineLayout(), 0, 1, &set, 0,
                            nullptr);
    uint32_t timed = 0;
    for (size_t i = 0; i < dispatches.size(); ++i) {
        const Dispatch& d = dispatches[i];
        if (d.groups == 0) continue;
        const uint32_t first = 2 * timed++;
        if (bound[i] != VK_NULL_HANDLE) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, bound[i]);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queryPool, first);
        if (d.stage == STAGE_CLEAR && info_.isCpu) {
            // On a CPU device the clear stage's stores run one scalar store per SIMD lane; the driver's
            // fill writes the same values (compute_glsl/clear.comp) at memset speed.
            fillForClear(cmd, params);
            vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool, first + 1);
            memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          kBufferUserStages, kBufferUserAccess);
            continue;
        }
        // More groups than the device takes in one dispatch (lavapipe: 65,535) run as several
        // dispatches with a base group: gl_WorkGroupID, and so gl_GlobalInvocationID, counts on
        // across them, which is all the stages use.
        for (uint32_t base = 0; base < d.groups; base += maxGroups)
            vkCmdDispatchBase(cmd, base, 0, 0, std::min(maxGroups, d.groups - base), 1, 1);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool, first + 1);
        // Each stage reads what the previous ones wrote. The transfer bits reach past this
        // submission (barriers follow submission order) and cover the downloads and uploads that
        // come after it.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      kBufferUserStages, kBufferUserAccess);
    }
    SR_TRY(context_.submitAndWait());
    savePipelineCache();
    // One entry per dispatch, 0 for those that recorded nothing.
    std::vector<double> timedMs;
    if (pairs > 0) SR_TRY(context_.readTimestampPairs(pairs, timedMs));
    gpuMs.assign(dispatches.size(), 0.0);
    for (size_t i = 0, k = 0; i < dispatches.size(); ++i)
        if (dispatches[i].groups > 0) gpuMs[i] = timedMs[k++];
    return okStatus();
}

}  // namespace

Result<std::unique_ptr<ComputeDevice>> makeVulkanDevice(int index)
{
    auto device = std::make_unique<VulkanDevice>();
    SR_TRY(device->init(index, nullptr));
    return std::unique_ptr<ComputeDevice>(std::move(device));
}

Result<std::unique_ptr<ComputeDevice>> makeVulkanPresentingDevice(int index, const PresentTarget& target)
{
    auto device = std::make_unique<VulkanDevice>();
    SR_TRY(device->init(index, &target));
    return std::unique_ptr<ComputeDevice>(std::move(device));
}

std::optional<VulkanPresentSource> vulkanPresentSource(ComputeDevice& device)
{
    auto* vulkan = dynamic_cast<VulkanDevice*>(&device);
    if (vulkan == nullptr) return std::nullopt;
    return VulkanPresentSource{&vulkan->context(), vulkan->buffer(BUF_FRAMEBUFFER)};
}

Status injectVulkanValidationError(ComputeDevice& device, const char* message)
{
    auto* vulkan = dynamic_cast<VulkanDevice*>(&device);
    if (vulkan == nullptr) return makeError(ExitCode::Usage, "vulkan: not a Vulkan device");
    return vulkan->injectValidationError(message);
}

}  // namespace sr
