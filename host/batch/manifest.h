// manifest.h - the job list of `raster batch`: JSON Lines, one job per line, with the options of
// `raster render` as keys (every setting of the schema, `raster settings`, by its key; and scene,
// output/png, aov/exr, stats, frames, orbit, id, png_compression, exr_compression).
// The output's extension selects its format: .png, or .npy for the raw RGBA8 array ("png" takes .png only).
//
//   {"defaults": {"width": 256, "height": 256, "shading": "lambert"}}      optional first line
//   {"scene": "bunny.obj", "camera": "orbit:30,20,3", "output": "bunny.png", "aov": "bunny.exr"}
//   {"scene": "builtin", "orbit": "0:360", "frames": 120, "output": "tt/f_%04d.png"}
//
// A job's value wins over the header's, which wins over the command line's (`raster batch --width ...`).
// Relative paths (scene, outputs) are relative to the manifest's folder; scenes named builtin... are the
// procedural ones. Every problem is one line naming the manifest and the line.
#ifndef RASTER_BATCH_MANIFEST_H
#define RASTER_BATCH_MANIFEST_H

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "io/image_io.h"
#include "settings/render_settings.h"

namespace sr {

struct ManifestJob {
    int line = 0;         // 1-based line of the manifest
    std::string id;       // "id": a label for reports; the output path when absent
    std::string scene;    // a file (resolved against the manifest's folder) or a builtin... name
    std::string orbit;    // `--orbit AZ0:AZ1` with frames > 0 (checked where frames are expanded)
    uint32_t frames = 0;  // `--frames N`: a turntable of N frames (0: one render)
    // Every render setting of the schema (settings/schema.h) under its key: width, camera, shading,
    // texture_filter, tessellate, ...; those the job does not name at `raster render`'s defaults.
    RenderOptions options = imageRenderOptions();
    std::string output, aov, stats;  // resolved paths (patterns when frames > 0); aov, stats may be empty
    std::string outputPattern, aovPattern, statsPattern;  // the same as written (joined after expansion)
    ImageEncoding encoding;                               // png_compression, exr_compression
    // Every setting that decides the images, with the defaults filled in and the paths as written:
    // equal for two jobs exactly when they render the same files (the sidecar records it).
    nlohmann::json canonical;
};

struct Manifest {
    std::string path;     // as given, for messages
    std::string baseDir;  // relative paths are joined to it (empty: used as written)
    std::vector<ManifestJob> jobs;
};

// Parses manifest `text`; `name` prefixes messages ("NAME:LINE: ..."), relative paths are joined to
// `baseDir` (empty: as written), and `commandLine` holds defaults under the header's (same keys; an
// invalid one is reported as "command line: ...").
Result<Manifest> parseManifest(const std::string& text, const std::string& name, const std::string& baseDir,
                               const nlohmann::json& commandLine);

// Reads and parses the file at `path` (relative paths in it against its folder).
Result<Manifest> loadManifest(const std::string& path, const nlohmann::json& commandLine);

// `path` joined to `baseDir` when it is relative (and baseDir is not empty).
std::string joinPath(const std::string& baseDir, const std::string& path);

// The keys a job may have: the job's own, then every setting's.
const std::vector<std::string>& manifestKeys();

}  // namespace sr

#endif  // RASTER_BATCH_MANIFEST_H
