// pipeline_cache.cpp - see pipeline_cache.h.
#include "vulkan/pipeline_cache.h"

#include <sys/stat.h>

#include <cstdlib>
#include <cstring>
#include <mutex>

#include "io/file_write.h"
#include "loaders/safe_file.h"

namespace sr {
namespace {

constexpr char kMagic[8] = {'R', 'A', 'S', 'T', 'E', 'R', 'P', 'C'};
// 2: the data holds the specialized modules after the driver's bytes.
constexpr uint32_t kFormatVersion = 2;
// magic, format version, reserved, data length (8 bytes), FNV-1a 64 of the data (8 bytes)
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;
// Far above what a driver keeps for these few pipelines; a larger file is not read.
constexpr uint64_t kMaxCacheFileBytes = uint64_t(256) << 20;

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

uint64_t fnv1a(const void* data, size_t bytes)
{
    const unsigned char* p = static_cast<const unsigned char*>(data);
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

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

bool olderPipelineCacheFormat(const std::vector<unsigned char>& file)
{
    return file.size() >= kHeaderBytes && std::memcmp(file.data(), kMagic, sizeof kMagic) == 0 &&
           get(file, 8, 4) < kFormatVersion;
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

std::vector<unsigned char> pipelineCacheDataBytes(const PipelineCacheContents& contents)
{
    // The driver's length and bytes; the number of modules; each module's key length, key, word count
    // and words. Every number little-endian, of 8 bytes for the driver's length and 4 elsewhere.
    size_t bytes = 8 + contents.driverData.size() + 4;
    for (const auto& [key, words] : contents.modules) bytes += 4 + key.size() + 4 + 4 * words.size();
    std::vector<unsigned char> out(bytes);
    size_t at = 0;
    put(out, at, contents.driverData.size(), 8);
    at += 8;
    if (!contents.driverData.empty())
        std::memcpy(&out[at], contents.driverData.data(), contents.driverData.size());
    at += contents.driverData.size();
    put(out, at, contents.modules.size(), 4);
    at += 4;
    for (const auto& [key, words] : contents.modules) {
        put(out, at, key.size(), 4);
        at += 4;
        if (!key.empty()) std::memcpy(&out[at], key.data(), key.size());
        at += key.size();
        put(out, at, words.size(), 4);
        at += 4;
        for (uint32_t w : words) {
            put(out, at, w, 4);
            at += 4;
        }
    }
    return out;
}

bool pipelineCacheContents(const std::vector<unsigned char>& data, PipelineCacheContents& contents,
                           std::string& why)
{
    contents = {};
    PipelineCacheContents read;
    size_t at = 0;
    // Whether `n` more bytes are there; every length read below is checked against what is left.
    auto fits = [&](uint64_t n) { return n <= data.size() - at; };
    if (!fits(8)) {
        why = "its data ends before the driver's length";
        return false;
    }
    uint64_t driverBytes = get(data, at, 8);
    at += 8;
    if (!fits(driverBytes) || !fits(driverBytes + 4)) {
        why = "its data ends inside the driver's bytes";
        return false;
    }
    read.driverData.assign(data.begin() + at, data.begin() + at + driverBytes);
    at += driverBytes;
    uint64_t count = get(data, at, 4);
    at += 4;
    for (uint64_t m = 0; m < count; ++m) {
        if (!fits(4) || !fits(4 + get(data, at, 4) + 4)) {
            why = fmt::format("its data ends inside module {} of {}", m + 1, count);
            return false;
        }
        uint64_t keyBytes = get(data, at, 4);
        std::string key(reinterpret_cast<const char*>(data.data() + at + 4), keyBytes);
        at += 4 + keyBytes;
        uint64_t words = get(data, at, 4);
        at += 4;
        if (!fits(4 * words)) {
            why = fmt::format("its data ends inside module {} of {}", m + 1, count);
            return false;
        }
        std::vector<uint32_t> module(words);
        for (uint64_t w = 0; w < words; ++w) module[w] = uint32_t(get(data, at + 4 * w, 4));
        at += 4 * words;
        read.modules[key] = std::move(module);
    }
    if (at != data.size()) {
        why = fmt::format("{} bytes of data after the last module", data.size() - at);
        return false;
    }
    contents = std::move(read);
    return true;
}

PipelineCache::~PipelineCache()
{
    if (cache_ != VK_NULL_HANDLE) vkDestroyPipelineCache(device_, cache_, nullptr);
}

Status PipelineCache::open(VkDevice device, const std::string& path)
{
    device_ = device;
    path_ = path;
    PipelineCacheContents contents;
    struct stat fileInfo {};
    if (!path.empty() && ::stat(path.c_str(), &fileInfo) == 0) {
        // Whatever is wrong with the file, the run goes on without its data and save() replaces it.
        Result<std::vector<unsigned char>> file =
            readRegularFile(path, kMaxCacheFileBytes, "read pipeline cache");
        std::string why;
        if (file) {
            std::vector<unsigned char> data = pipelineCacheData(*file, why);
            if (why.empty()) pipelineCacheContents(data, contents, why);
        } else {
            why = file.error().message;
        }
        // A file an earlier raster wrote is replaced without a word: nothing is wrong with it.
        if (file && olderPipelineCacheFormat(*file)) why.clear();
        if (!why.empty())
            fmt::print(stderr, "warning: pipeline cache '{}' not used ({}); it is rebuilt\n", path, why);
    }
    std::vector<unsigned char>& data = contents.driverData;
    modules_ = std::move(contents.modules);
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

const std::vector<uint32_t>* PipelineCache::module(const std::string& key) const
{
    auto found = modules_.find(key);
    return found == modules_.end() ? nullptr : &found->second;
}

void PipelineCache::addModule(const std::string& key, std::vector<uint32_t> words)
{
    modules_[key] = std::move(words);
    modulesAdded_ = true;
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
    if (data.size() == savedBytes_ && hash == savedHash_ && !modulesAdded_) return okStatus();
    SR_TRY(createParentFolder(path_));
    // Devices of one model share the file, and the temporary name it is written under is the process's
    // (temporaryPath): two devices of one process (raster batch --devices all) save one at a time.
    static std::mutex saving;
    std::lock_guard<std::mutex> lock(saving);
    PipelineCacheContents contents;
    contents.driverData = std::move(data);
    contents.modules = modules_;
    std::vector<unsigned char> file = pipelineCacheFileBytes(pipelineCacheDataBytes(contents));
    SR_TRY(writeFileAtomically(path_, file.data(), file.size()));
    savedBytes_ = contents.driverData.size();
    savedHash_ = hash;
    modulesAdded_ = false;
    return okStatus();
}

}  // namespace sr
