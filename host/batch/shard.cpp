// shard.cpp - shard and device choice for `raster batch`.
#include "batch/shard.h"

#include <algorithm>
#include <cstdlib>

namespace sr {
namespace {

// A decimal integer in [0, 2^31): digits only, no sign, no spaces.
bool parseIndex(const std::string& text, uint32_t& out)
{
    if (text.empty() || text.size() > 10) return false;
    uint64_t value = 0;
    for (char c : text) {
        if (c < '0' || c > '9') return false;
        value = value * 10 + uint64_t(c - '0');
    }
    if (value > 0x7fffffffu) return false;
    out = uint32_t(value);
    return true;
}

}  // namespace

Result<Shard> parseShardSpec(const std::string& text)
{
    const size_t slash = text.find('/');
    Shard shard;
    shard.source = "--shard";
    if (slash == std::string::npos || !parseIndex(text.substr(0, slash), shard.index) ||
        !parseIndex(text.substr(slash + 1), shard.count) || shard.count == 0 || shard.index >= shard.count)
        return makeError(ExitCode::Usage, "invalid --shard '{}': expected i/N with 0 <= i < N (e.g. 0/4)",
                         text);
    return shard;
}

Result<Shard> shardFromEnvironment(const std::map<std::string, std::string>& env)
{
    auto get = [&](const char* name) -> const std::string* {
        auto it = env.find(name);
        return it == env.end() || it->second.empty() ? nullptr : &it->second;
    };
    const std::string* id = get("SLURM_ARRAY_TASK_ID");
    if (!id) return Shard{};
    auto number = [&](const char* name, uint32_t& out) -> Status {
        const std::string* text = get(name);
        if (!text || !parseIndex(*text, out))
            return makeError(ExitCode::Usage, "invalid {} '{}': expected a non-negative integer", name,
                             text ? *text : "");
        return okStatus();
    };
    uint32_t task = 0;
    SR_TRY(number("SLURM_ARRAY_TASK_ID", task));
    Shard shard;
    shard.source = "slurm";
    if (get("SLURM_ARRAY_TASK_MIN") && get("SLURM_ARRAY_TASK_MAX")) {
        uint32_t min = 0, max = 0, step = 1;
        SR_TRY(number("SLURM_ARRAY_TASK_MIN", min));
        SR_TRY(number("SLURM_ARRAY_TASK_MAX", max));
        if (get("SLURM_ARRAY_TASK_STEP")) SR_TRY(number("SLURM_ARRAY_TASK_STEP", step));
        uint32_t count = 0;
        const bool countGiven = get("SLURM_ARRAY_TASK_COUNT") != nullptr;
        if (countGiven) SR_TRY(number("SLURM_ARRAY_TASK_COUNT", count));
        // Slurm sets a step only for a regular range; a list of ids is regular when its count says so.
        if (step == 0 || min > max || task < min || task > max || (task - min) % step != 0 ||
            (countGiven && count != (max - min) / step + 1))
            return makeError(ExitCode::Usage,
                             "the Slurm array (task {}, ids {} to {}, step {}{}) is not one regular range: "
                             "submit --array=0-N-1 or pass --shard i/N",
                             task, min, max, step, countGiven ? fmt::format(", {} tasks", count) : "");
        shard.index = (task - min) / step;
        shard.count = (max - min) / step + 1;
        return shard;
    }
    if (get("SLURM_ARRAY_TASK_COUNT")) {
        SR_TRY(number("SLURM_ARRAY_TASK_COUNT", shard.count));
        if (shard.count == 0 || task >= shard.count)
            return makeError(ExitCode::Usage,
                             "SLURM_ARRAY_TASK_ID {} is not below SLURM_ARRAY_TASK_COUNT {}: submit "
                             "--array=0-N-1 or pass --shard i/N",
                             task, shard.count);
        shard.index = task;
        return shard;
    }
    return makeError(
        ExitCode::Usage,
        "SLURM_ARRAY_TASK_ID is set without SLURM_ARRAY_TASK_COUNT or _MIN/_MAX: pass --shard i/N");
}

Result<Shard> chooseShard(const std::string& flag, const std::map<std::string, std::string>& env)
{
    return flag.empty() ? shardFromEnvironment(env) : parseShardSpec(flag);
}

std::map<std::string, std::string> slurmEnvironment()
{
    std::map<std::string, std::string> env;
    for (const char* name : {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN",
                             "SLURM_ARRAY_TASK_MAX", "SLURM_ARRAY_TASK_STEP"})
        if (const char* value = std::getenv(name)) env[name] = value;
    return env;
}

Result<DeviceList> parseDeviceList(const std::string& text)
{
    DeviceList list;
    if (text == "all") {
        list.all = true;
        return list;
    }
    auto invalid = [&](const std::string& why) {
        return makeError(ExitCode::Usage, "invalid --devices '{}': {}; expected all or indices like 0,1",
                         text, why);
    };
    size_t start = 0;
    for (;;) {
        const size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma == std::string::npos ? comma : comma - start);
        uint32_t index = 0;
        if (!parseIndex(item, index)) return invalid(fmt::format("'{}' is not a device index", item));
        if (std::find(list.indices.begin(), list.indices.end(), int(index)) != list.indices.end())
            return invalid(fmt::format("device {} listed twice", index));
        list.indices.push_back(int(index));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return list;
}

}  // namespace sr
