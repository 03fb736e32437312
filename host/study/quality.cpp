// quality.cpp - see quality.h.
#include "study/quality.h"

#include "settings/schema.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "settings/schema.h"

namespace sr {
namespace {

// A row's number under `key`; "inf" stands for +infinity (JSON has none: an identical image's PSNR).
Result<double> rowNumber(const nlohmann::json& row, const char* key)
{
    if (row.is_object() && row.contains(key)) {
        const nlohmann::json& v = row[key];
        if (v.is_number()) return v.get<double>();
        if (v.is_string() && v.get<std::string>() == "inf") return std::numeric_limits<double>::infinity();
    }
    return makeError(ExitCode::Usage, "accuracy row without a number \"{}\": {}", key, row.dump());
}

Result<std::string> rowString(const nlohmann::json& row, const char* key)
{
    if (row.is_object() && row.contains(key) && row[key].is_string()) return row[key].get<std::string>();
    return makeError(ExitCode::Usage, "accuracy row without a string \"{}\": {}", key, row.dump());
}

std::string psnrText(double psnr)
{
    return std::isinf(psnr) ? "exact" : fmt::format("{:.2f} dB", psnr);
}

}  // namespace

Result<QualityTarget> parseQualityTarget(const std::string& text)
{
    const std::string prefix = "psnr:";
    if (text.compare(0, prefix.size(), prefix) != 0)
        return makeError(ExitCode::Usage,
                         "invalid --quality '{}': expected psnr:N (the metric is PSNR, N in dB)", text);
    const std::string number = text.substr(prefix.size());
    char* end = nullptr;
    errno = 0;
    const double psnr = std::strtod(number.c_str(), &end);
    if (number.empty() || end != number.c_str() + number.size() || errno != 0 || !std::isfinite(psnr) ||
        psnr <= 0.0)
        return makeError(ExitCode::Usage,
                         "invalid --quality '{}': N in psnr:N must be a positive number of dB", text);
    return QualityTarget{text, psnr};
}

Result<nlohmann::json> accuracyRowsFor(const nlohmann::json& study, const std::string& scene,
                                       const std::string& backend)
{
    if (!study.is_object() || !study.contains("accuracy") || !study["accuracy"].is_array())
        return makeError(ExitCode::Usage, "not a raster study JSON: no \"accuracy\" list");
    nlohmann::json rows = nlohmann::json::array();
    std::set<std::string> pairs;
    for (const nlohmann::json& row : study["accuracy"]) {
        auto s = rowString(row, "scene");
        auto b = rowString(row, "backend");
        if (!s) return s.error();
        if (!b) return b.error();
        if (*s == scene && *b == backend) rows.push_back(row);
        pairs.insert(*s + " on " + *b);
    }
    if (rows.empty()) {
        std::string held;
        for (const std::string& p : pairs) held += (held.empty() ? "" : ", ") + p;
        return makeError(ExitCode::Usage, "the study has no rows for scene '{}' on {} (it has: {})", scene,
                         backend, held.empty() ? "nothing" : held);
    }
    return rows;
}

Result<nlohmann::json> pickCheapest(const nlohmann::json& rows, const QualityTarget& target)
{
    if (!rows.is_array() || rows.empty())
        return makeError(ExitCode::Usage, "no accuracy rows to choose from");
    const nlohmann::json* best = nullptr;
    double bestMs = 0.0, bestMemory = 0.0;
    // The best PSNR on offer, for the message when nothing meets the target.
    const nlohmann::json* sharpest = nullptr;
    double sharpestPsnr = -std::numeric_limits<double>::infinity();
    for (const nlohmann::json& row : rows) {
        // A row without a PSNR (the reference itself, in a hand-made file) has nothing to offer.
        if (row.is_object() && row.contains("psnr") && row["psnr"].is_null()) continue;
        auto psnr = rowNumber(row, "psnr");
        auto ms = rowNumber(row, "ms");
        auto memory = rowNumber(row, "memory_mib");
        if (!psnr) return psnr.error();
        if (!ms) return ms.error();
        if (!memory) return memory.error();
        if (*psnr > sharpestPsnr) {
            sharpestPsnr = *psnr;
            sharpest = &row;
        }
        if (!(*psnr >= target.psnr)) continue;
        if (!best || *ms < bestMs || (*ms == bestMs && *memory < bestMemory)) {
            best = &row;
            bestMs = *ms;
            bestMemory = *memory;
        }
    }
    if (!sharpest) return makeError(ExitCode::Usage, "no accuracy row with a PSNR to choose from");
    if (!best) {
        auto label = rowString(*sharpest, "setting");
        return makeError(ExitCode::Usage, "no setting meets --quality {}: the best is {} at PSNR {}",
                         target.text, label ? *label : "?", psnrText(sharpestPsnr));
    }
    return *best;
}

Result<StudySetting> settingFromRow(const nlohmann::json& row)
{
    StudySetting s;
    auto group = rowString(row, "group");
    auto label = rowString(row, "setting");
    auto method = rowString(row, "method");
    auto filter = rowString(row, "texture_filter");
    auto uv = rowString(row, "uv");
    auto msaa = rowNumber(row, "msaa");
    auto ssaa = rowNumber(row, "ssaa");
    for (const Result<std::string>* r : {&group, &label, &method, &filter, &uv})
        if (!*r) return r->error();
    if (!msaa) return msaa.error();
    if (!ssaa) return ssaa.error();
    s.group = *group;
    s.label = *label;
    auto m = rasterMethodFromName(*method);
    auto f = textureFilterFromName(*filter);
    auto u = uvInterpolationFromName(*uv);
    if (!m) return m.error();
    if (!f) return f.error();
    if (!u) return u.error();
    s.rasterMethod = *m;
    s.textureFilter = *f;
    s.uvInterpolation = *u;
    s.msaa = uint32_t(*msaa);
    s.ssaa = uint32_t(*ssaa);
    // Rows of studies before tessellation have no tessellation keys: off.
    if (row.contains("tessellate")) {
        auto mode = rowNumber(row, "tessellate");
        auto edge = rowNumber(row, "tess_edge_px");
        auto level = rowNumber(row, "tess_max_level");
        if (!mode || !edge || !level || *mode < 0 || *mode > TESS_CENTROID)
            return makeError(ExitCode::Usage, "accuracy row with invalid tessellation keys: {}", row.dump());
        s.tessellate = uint32_t(*mode);
        s.tessEdgePx = float(*edge);
        s.tessMaxLevel = uint32_t(*level);
    }
    // The schema's rule for each (settings/schema.h), on the numbers as the row holds them.
    if (!checkSettingValue(setting("msaa"), row["msaa"], "msaa") ||
        !checkSettingValue(setting("ssaa"), row["ssaa"], "ssaa"))
        return makeError(ExitCode::Usage, "accuracy row with an invalid msaa or ssaa: {}", row.dump());
    return s;
}

std::string describeChoice(const QualityTarget& target, const nlohmann::json& row,
                           const StudySetting& setting)
{
    auto psnr = rowNumber(row, "psnr");
    auto ms = rowNumber(row, "ms");
    auto memory = rowNumber(row, "memory_mib");
    std::string uv = setting.uvInterpolation == UV_PERSPECTIVE
                         ? ""
                         : fmt::format(", uv {}", uvInterpolationName(setting.uvInterpolation));
    return fmt::format("quality {} -> {} ({}, msaa {}, ssaa {}, filter {}{}): PSNR {}, {:.3f} ms, {:.1f} MiB",
                       target.text, setting.label, rasterMethodName(setting.rasterMethod), setting.msaa,
                       setting.ssaa, textureFilterName(setting.textureFilter), uv,
                       psnr ? psnrText(*psnr) : "?", ms ? *ms : 0.0, memory ? *memory : 0.0);
}

}  // namespace sr
