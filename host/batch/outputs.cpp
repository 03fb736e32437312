// outputs.cpp - sidecars of batch jobs and the leftovers of killed runs.
#include "batch/outputs.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include <unistd.h>

#include "loaders/safe_file.h"

namespace sr {

namespace fs = std::filesystem;

// A sidecar holds one job's settings: a few kB. Anything far larger is not one of ours.
constexpr uint64_t kMaxSidecarBytes = 1u << 24;

std::string sidecarPath(const std::string& png)
{
    return png + ".job.json";
}

nlohmann::json sidecarJson(const nlohmann::json& settings, const std::string& scenePath)
{
    nlohmann::json sidecar{{"job", settings}};
    std::error_code ec;
    if (scenePath.compare(0, 7, "builtin") != 0 && fs::is_regular_file(scenePath, ec)) {
        const auto size = fs::file_size(scenePath, ec);
        const auto time = fs::last_write_time(scenePath, ec);
        if (!ec)
            sidecar["scene_file"] = {{"bytes", size},
                                     {"modified_ns", int64_t(time.time_since_epoch().count())}};
    }
    return sidecar;
}

bool jobComplete(const std::string& sidecar, const nlohmann::json& expected,
                 const std::vector<std::string>& outputs)
{
    // Whatever is at the sidecar's path (a folder, a FIFO, a huge file) only makes the job not done; the
    // job's commit then reports why its sidecar cannot be written.
    auto text = readRegularFile(sidecar, kMaxSidecarBytes, "read");
    if (!text) return false;
    const nlohmann::json recorded = nlohmann::json::parse(text->begin(), text->end(), nullptr, false);
    if (recorded.is_discarded() || recorded != expected) return false;
    std::error_code ec;
    for (const std::string& path : outputs)
        if (!fs::is_regular_file(path, ec)) return false;
    return true;
}

size_t removeTemporaries(const std::vector<std::string>& finals)
{
    // One listing per folder, whatever the number of jobs in it.
    std::map<std::string, std::set<std::string>> byFolder;
    for (const std::string& path : finals) {
        const fs::path p(path);
        byFolder[p.parent_path().empty() ? "." : p.parent_path().string()].insert(p.filename().string());
    }
    size_t removed = 0;
    for (const auto& [folder, names] : byFolder) {
        std::error_code ec;
        for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
            // Only a leftover: the temporary of a process still writing (another batch on the same
            // folder) is its own to rename.
            const auto t = temporaryName(it->path().filename().string());
            if (!t || !t->writerGone || !names.count(t->finalName)) continue;
            std::error_code removeError;
            if (fs::remove(it->path(), removeError)) ++removed;
        }
    }
    return removed;
}

}  // namespace sr
