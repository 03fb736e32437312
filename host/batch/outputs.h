// outputs.h - the files of a batch job, written so that a killed batch never leaves a final name that a
// rerun would trust: each file is written under a temporary name and renamed into place
// (io/file_write.h), and the job's sidecar (NAME.job.json: the settings that produced the files) is written last. A job counts as done
// exactly when its sidecar records the settings asked for now and every output exists.
//
// The renames protect against a killed process, not against a power cut (nothing is fsynced).
#ifndef RASTER_BATCH_OUTPUTS_H
#define RASTER_BATCH_OUTPUTS_H

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "io/file_write.h"

namespace sr {

// `png` + ".job.json".
std::string sidecarPath(const std::string& png);

// What a sidecar holds for a job: its settings, and the scene file's size and modification time so that
// an edited scene renders again (procedural scenes and unreadable files have none).
nlohmann::json sidecarJson(const nlohmann::json& settings, const std::string& scenePath);

// Whether the job is done: the sidecar at `sidecar` parses and equals `expected`, and every one of
// `outputs` exists.
bool jobComplete(const std::string& sidecar, const nlohmann::json& expected,
                 const std::vector<std::string>& outputs);

// Removes the leftovers of killed runs: temporary files (temporaryName) of any F in `finals` whose
// writer is gone, in the folders that hold them; those of a process still running (another batch
// writing into the same folder) stay. Returns how many were removed.
size_t removeTemporaries(const std::vector<std::string>& finals);

}  // namespace sr

#endif  // RASTER_BATCH_OUTPUTS_H
