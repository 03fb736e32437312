// shard.h - which jobs of a batch this process renders (`--shard i/N`, or a Slurm job array's task) and
// on which devices (`--devices 0,1|all`). Pure functions of their text and environment, so each rule is
// tested without a scheduler.
#ifndef RASTER_BATCH_SHARD_H
#define RASTER_BATCH_SHARD_H

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

// Shard `index` of `count` renders the jobs whose position in the expanded manifest is congruent to
// `index` modulo `count`, so N shards cover every job exactly once whatever the manifest's order.
struct Shard {
    uint32_t index = 0;
    uint32_t count = 1;
    std::string source = "none";  // where it came from: "--shard", "slurm" or "none" (every job)
};

// `--shard i/N`: 0 <= i < N, both decimal integers.
Result<Shard> parseShardSpec(const std::string& text);

// The Slurm job array's task, when `env` has SLURM_ARRAY_TASK_ID: shard (id - min) / step of
// (max - min) / step + 1 from SLURM_ARRAY_TASK_MIN, _MAX and _STEP (step 1 when absent), else shard id
// of SLURM_ARRAY_TASK_COUNT. An array whose ids are not one regular range (--array=1,4,9) has no such
// numbering and is an error; so is a task id without either. No SLURM_ARRAY_TASK_ID: every job.
Result<Shard> shardFromEnvironment(const std::map<std::string, std::string>& env);

// `--shard` when given (non-empty), else the environment's.
Result<Shard> chooseShard(const std::string& flag, const std::map<std::string, std::string>& env);

// The SLURM_ARRAY_* variables of this process's environment.
std::map<std::string, std::string> slurmEnvironment();

inline bool inShard(const Shard& shard, size_t job)
{
    return job % shard.count == shard.index;
}

// `--devices`: "all" (every device of the backend; `all` is set) or a comma-separated list of distinct
// device indices.
struct DeviceList {
    bool all = false;
    std::vector<int> indices;
};
Result<DeviceList> parseDeviceList(const std::string& text);

}  // namespace sr

#endif  // RASTER_BATCH_SHARD_H
