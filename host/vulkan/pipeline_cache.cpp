// pipeline_cache.cpp - see pipeline_cache.h.
#include "vulkan/pipeline_cache.h"

#include <sys/stat.h>

#include <cstdlib>
#include <cstring>

#include "io/file_write.h"
#include "scene/safe_file.h"

namespace sr {
namespace {

constexpr char kMagic[8] = {'R', 'A', 'S', 'T', 'E', 'R', 'P', 'C'};
constexpr uint32_t kFormatVersion = 1;
// magic, format version, reserved, data length (8 bytes), FNV-1a 64 of the data (8 bytes)
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;
// Far above what a driver keeps for these few pipelines; a larger file is not read.
constexpr uint64_t kMaxCacheFileBytes = uint64_t(256) << 20;

uint64_t fnv1a(const unsigned char* data, size_t bytes)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < bytes; ++i) h = (h ^ data[i]) * 0x100000001b3ull;
    return h;
}

void put(std::vector<unsigned char>& out, size_t at, uint64_t value, size_t bytes)
{
    for (size_t k = 0; k < bytes; ++k) out[at + k] = static_cast<unsigned char>(value >> (8 * k));
}

uint64_t get(const std::vector<unsigned char>& in, size_t at, size_t bytes)
{
    uint64_t value = 0;
    for (size_t k = bytes; k-- > 0;) value = value << 8 | in[at + k];
    return value;
}

std::string cacheFolder()
{
    const char* chosen = std::getenv("RASTER_PIPELINE_CACHE");
    if (chosen && *chosen) return std::string(chosen) == "off" ? std::string() : std::string(chosen);
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    if (xdg && *xdg == '/') return std::string(xdg) + "/raster";
    const char* home = std::getenv("HOME");
    if (home && *home == '/') return std::string(home) + "/.cache/raster";
    return {};
}

}  // namespace

std::string pipelineCacheFile(const VkPhysicalDeviceProperties& properties)
{
    std::string folder = cacheFolder();
    if (folder.empty()) return {};
    std::string uuid;
    for (uint8_t b : properties.pipelineCacheUUID) uuid += fmt::format("{:02x}", b);
    return fmt::format("{}/compute-{:04x}-{:04x}-{:08x}-{}.bin", folder, properties.vendorID,
                       properties.deviceID, properties.driverVersion, uuid);
}

std::vector<unsigned char> pipelineCacheData(const std::vector<unsigned char>& file, std::string& why)
{
    if (file.size() < kHeaderBytes || std::memcmp(file.data(), kMagic, sizeof kMagic) != 0) {
        why = "not a raster pipeline cache";
        return {};
    }
    if (get(file, 8, 4) != kFormatVersion) {
        why = fmt::format("format version {}, not {}", get(file, 8, 4), kFormatVersion);
        return {};
    }
    uint64_t length = get(file, 16, 8);
    if (length != file.size() - kHeaderBytes) {
        why = fmt::format("{} bytes of data where the header says {}", file.size() - kHeaderBytes, length);
        return {};
    }
    if (get(file, 24, 8) != fnv1a(file.data() + kHeaderBytes, size_t(length))) {
        why = "its data does not match its checksum";
        return {};
    }
    return std::vector<unsigned char>(file.begin() + kHeaderBytes, file.end());
}

std::vector<unsigned char> pipelineCacheFileBytes(const std::vector<unsigned char>& data)
{
    std::vector<unsigned char> out(kHeaderBytes + data.size());
    std::memcpy(out.data(), kMagic, sizeof kMagic);
    put(out, 8, kFormatVersion, 4);
    put(out, 16, data.size(), 8);
    put(out, 24, fnv1a(data.data(), data.size()), 8);
    if (!data.empty()) std::memcpy(out.data() + kHeaderBytes, data.data(), data.size());
    return out;
}

PipelineCache::~PipelineCache()
{
    if (cache_ != VK_NULL_HANDLE) vkDestroyPipelineCache(device_, cache_, nullptr);
}

Status PipelineCache::open(VkDevice device, const std::string& path)
{
    device_ = device;
    path_ = path;
    std::vector<unsigned char> data;
    struct stat fileInfo {};
    if (!path.empty() && ::stat(path.c_str(), &fileInfo) == 0) {
        // Whatever is wrong with the file, the run goes on without its data and save() replaces it.
        Result<std::vector<unsigned char>> file =
            readRegularFile(path, kMaxCacheFileBytes, "read pipeline cache");
        std::string why;
        if (file)
            data = pipelineCacheData(*file, why);
        else
            why = file.error().message;
        if (!why.empty())
            fmt::print(stderr, "warning: pipeline cache '{}' not used ({}); it is rebuilt\n", path, why);
    }
    VkPipelineCacheCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
    info.initialDataSize = data.size();
    info.pInitialData = data.empty() ? nullptr : data.data();
    VkResult result = vkCreatePipelineCache(device, &info, nullptr, &cache_);
    if (result != VK_SUCCESS && !data.empty()) {
        // A driver may refuse data it does not like instead of ignoring it: start empty.
        info.initialDataSize = 0;
        info.pInitialData = nullptr;
        data.clear();
        result = vkCreatePipelineCache(device, &info, nullptr, &cache_);
    }
    if (result != VK_SUCCESS)
        return makeError(ExitCode::Runtime, "vkCreatePipelineCache failed ({})", int(result));
    loadedBytes_ = data.size();
    savedBytes_ = data.size();
    savedHash_ = fnv1a(data.data(), data.size());
    return okStatus();
}

Status PipelineCache::save()
{
    if (path_.empty() || cache_ == VK_NULL_HANDLE) return okStatus();
    size_t bytes = 0;
    VkResult result = vkGetPipelineCacheData(device_, cache_, &bytes, nullptr);
    if (result != VK_SUCCESS)
        return makeError(ExitCode::Runtime, "vkGetPipelineCacheData failed ({})", int(result));
    std::vector<unsigned char> data(bytes);
    result = vkGetPipelineCacheData(device_, cache_, &bytes, data.data());
    if (result != VK_SUCCESS && result != VK_INCOMPLETE)
        return makeError(ExitCode::Runtime, "vkGetPipelineCacheData failed ({})", int(result));
    data.resize(bytes);
    uint64_t hash = fnv1a(data.data(), data.size());
    if (data.size() == savedBytes_ && hash == savedHash_) return okStatus();
    SR_TRY(createParentFolder(path_));
    std::vector<unsigned char> file = pipelineCacheFileBytes(data);
    SR_TRY(writeFileAtomically(path_, file.data(), file.size()));
    savedBytes_ = data.size();
    savedHash_ = hash;
    return okStatus();
}

}  // namespace sr
