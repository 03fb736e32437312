// quality.h - "model no more than a scene needs" (issue 12, point 4): `raster render --quality psnr:N`
// picks, from the accuracy rows of `raster study` for the scene and backend, the cheapest setting whose
// image meets the target, and reports what it chose.
//
// Rows are the study JSON's "accuracy" entries: {"scene", "backend", "group", "setting", "method",
// "msaa", "ssaa", "texture_filter", "uv", "ms", "psnr" (a number, or "inf" for an image identical to the
// reference), "max_error", "memory_mib"}. Everything here is pure: the rows come from a study file or
// from measuring the scene (cli/study.h, measureAccuracy).
#ifndef RASTER_STUDY_QUALITY_H
#define RASTER_STUDY_QUALITY_H

#include <string>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "study/settings_study.h"

namespace sr {

// A quality target: the image's PSNR against the study's reference must be at least `psnr` dB.
struct QualityTarget {
    std::string text;  // as given, e.g. "psnr:40"
    double psnr = 0.0;
};

// Parses "psnr:N", N a finite positive number of dB; anything else is a one-line Usage error.
Result<QualityTarget> parseQualityTarget(const std::string& text);

// The rows of `study`'s "accuracy" list for `scene` on `backend`; a Usage error naming what the file
// holds when there are none.
Result<nlohmann::json> accuracyRowsFor(const nlohmann::json& study, const std::string& scene,
                                       const std::string& backend);

// Of `rows` (one scene, one backend), the one with the smallest "ms" whose PSNR meets the target, the
// smaller "memory_mib" between equal times (then the earlier row). None meeting it is a Usage error
// naming the best PSNR there is and its setting; a row without a number where one is needed is a
// Usage error too.
Result<nlohmann::json> pickCheapest(const nlohmann::json& rows, const QualityTarget& target);

// The setting a row describes ("group", "setting", "method", "msaa", "ssaa", "texture_filter", "uv").
Result<StudySetting> settingFromRow(const nlohmann::json& row);

// The line `raster render --quality` prints: "quality psnr:40 -> msaa4 (fixed8, msaa 4, ssaa 1, filter
// trilinear): PSNR 41.02 dB, 3.694 ms, 37.8 MiB", with ", uv affine" after the filter for affine UVs.
std::string describeChoice(const QualityTarget& target, const nlohmann::json& row,
                           const StudySetting& setting);

}  // namespace sr

#endif  // RASTER_STUDY_QUALITY_H
