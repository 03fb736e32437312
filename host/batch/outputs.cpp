// outputs.cpp - temporary names, renames and sidecars of batch jobs.
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

namespace sr {

namespace fs = std::filesystem;

std::string temporaryPath(const std::string& path)
{
    return fmt::format("{}.tmp.{}", path, getpid());
}

Status renameFile(const std::string& from, const std::string& to)
{
    if (std::rename(from.c_str(), to.c_str()) != 0)
        return makeError(ExitCode::Usage, "cannot rename '{}' to '{}': {}", from, to, std::strerror(errno));
    return okStatus();
}

Status writeFile(const std::string& tmp, const void* data, size_t bytes)
{
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) return makeError(ExitCode::Usage, "cannot write '{}': {}", tmp, std::strerror(errno));
    const bool written = std::fwrite(data, 1, bytes, f) == bytes;
    const int savedErrno = errno;
    if (std::fclose(f) != 0 || !written) {
        std::remove(tmp.c_str());
        return makeError(ExitCode::Usage, "cannot write '{}': {}", tmp,
                         std::strerror(written ? errno : savedErrno));
    }
    return okStatus();
}

Status writeFileAtomically(const std::string& path, const void* data, size_t bytes)
{
    const std::string tmp = temporaryPath(path);
    SR_TRY(writeFile(tmp, data, bytes));
    return renameFile(tmp, path);
}

Status createParentFolder(const std::string& path)
{
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty()) return okStatus();
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) return makeError(ExitCode::Usage, "cannot create folder '{}': {}", parent.string(), ec.message());
    return okStatus();
}

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
    std::ifstream in(sidecar);
    if (!in) return false;
    const nlohmann::json recorded = nlohmann::json::parse(in, nullptr, false);
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
            const std::string name = it->path().filename().string();
            const size_t tmp = name.rfind(".tmp.");
            if (tmp == std::string::npos || tmp + 5 == name.size() ||
                name.find_first_not_of("0123456789", tmp + 5) != std::string::npos ||
                !names.count(name.substr(0, tmp)))
                continue;
            std::error_code removeError;
            if (fs::remove(it->path(), removeError)) ++removed;
        }
    }
    return removed;
}

}  // namespace sr
