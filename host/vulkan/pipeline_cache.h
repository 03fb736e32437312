// pipeline_cache.h - the compute pipelines' VkPipelineCache, kept on disk between runs.
//
// Creating the pipelines dominates a short run (a 16x16 frame, a batch worker, a Python call): the
// driver translates and compiles every SPIR-V module. A VkPipelineCache lets a driver skip that for a
// pipeline it has built before, and its contents (vkGetPipelineCacheData) carry over to the next run.
// The file lives in the XDG cache folder, one per device and driver: RASTER_PIPELINE_CACHE names another
// folder, or "off" for none; else $XDG_CACHE_HOME/raster, else $HOME/.cache/raster.
//
// CPU devices also keep there the modules specialized to their constants (spirv_specialize.h), which
// lavapipe's own VkPipelineCache does not hold: specializing costs a warm start as much as creating the
// pipelines from the specialized modules does.
//
// The file is a header of our own (magic, format version, data length, FNV-1a hash of the data) and the
// data: the driver's bytes, then the specialized modules, each under its key. A file whose header, length or
// hash does not match (truncated, corrupted, another format) is not handed to the driver: the cache starts
// empty and the file is rewritten. A driver also checks its own header (vendor, device, pipelineCacheUUID)
// and ignores data of another driver. Writers write a temporary file and rename it into place
// (host/io/file_write.h), so concurrent runs never see a partial file; the last to finish wins, and either
// version is a valid cache.
#ifndef RASTER_PIPELINE_CACHE_H
#define RASTER_PIPELINE_CACHE_H

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

// FNV-1a, 64 bits, of `bytes` bytes at `data`: the file's checksum, and the modules' keys.
uint64_t fnv1a(const void* data, size_t bytes);

// The cache file for a device, or "" when the cache is off (RASTER_PIPELINE_CACHE=off, or no cache
// folder can be named): <folder>/compute-<vendorID>-<deviceID>-<driverVersion>-<pipelineCacheUUID>.bin.
std::string pipelineCacheFile(const VkPhysicalDeviceProperties& properties);

// The driver's data held in a cache file's bytes, or nothing (empty) when the bytes are not a complete,
// intact file of this format. `why` says what was wrong when it was not empty.
std::vector<unsigned char> pipelineCacheData(const std::vector<unsigned char>& file, std::string& why);

// Whether `file` is a cache file of an earlier format version, which is replaced without a warning.
bool olderPipelineCacheFormat(const std::vector<unsigned char>& file);

// The bytes of a cache file holding the driver's `data`.
std::vector<unsigned char> pipelineCacheFileBytes(const std::vector<unsigned char>& data);

// What a cache file's data holds: the driver's bytes and the specialized modules by key.
struct PipelineCacheContents {
    std::vector<unsigned char> driverData;
    std::map<std::string, std::vector<uint32_t>> modules;
};
std::vector<unsigned char> pipelineCacheDataBytes(const PipelineCacheContents& contents);
// The contents of a file's data, or false (with `why`, and `contents` empty) when its parts do not add
// up to it.
bool pipelineCacheContents(const std::vector<unsigned char>& data, PipelineCacheContents& contents,
                           std::string& why);

class PipelineCache {
public:
    PipelineCache() = default;
    PipelineCache(const PipelineCache&) = delete;
    PipelineCache& operator=(const PipelineCache&) = delete;
    ~PipelineCache();

    // Creates the cache on `device` from `path` (no file: empty; a damaged one: empty, with a warning).
    // An empty path makes a cache that is never saved.
    Status open(VkDevice device, const std::string& path);
    VkPipelineCache handle() const { return cache_; }
    // The module specialized under `key` (specializationKey), or null.
    const std::vector<uint32_t>* module(const std::string& key) const;
    void addModule(const std::string& key, std::vector<uint32_t> words);
    // Writes the cache to its file when the driver's data changed or modules were added since it was
    // loaded or last saved. A failure is returned, and leaves any earlier file in place.
    Status save();
    // The cache's file ("" when none) and how many bytes of driver data it was loaded with.
    const std::string& path() const { return path_; }
    size_t loadedBytes() const { return loadedBytes_; }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    VkPipelineCache cache_ = VK_NULL_HANDLE;
    std::string path_;
    size_t loadedBytes_ = 0;
    uint64_t savedHash_ = 0;  // hash of the data last loaded or saved
    size_t savedBytes_ = 0;
    std::map<std::string, std::vector<uint32_t>> modules_;
    bool modulesAdded_ = false;
};

}  // namespace sr

#endif  // RASTER_PIPELINE_CACHE_H
