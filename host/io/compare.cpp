// compare.cpp - see compare.h.
#include "io/compare.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace sr {
namespace {

bool endsWith(const std::string& s, const std::string& suffix)
{
    if (s.size() < suffix.size()) return false;
    return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                      [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

// Whether `count` items over a tolerance are within the allowed fraction of `total`.
bool withinFraction(uint64_t count, uint64_t total, double fraction)
{
    return double(count) <= std::floor(fraction * double(total));
}

bool isCompute(const std::string& backend)
{
    return backend == "cuda" || backend == "vulkan";
}

// 0 -> black, 0.33 -> red, 0.66 -> yellow, 1 -> white.
uint32_t heat(double t)
{
    t = std::clamp(t, 0.0, 1.0);
    auto channel = [](double v) { return uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
    uint32_t r = channel(t * 3.0), g = channel(t * 3.0 - 1.0), b = channel(t * 3.0 - 2.0);
    return r | (g << 8) | (b << 16) | (255u << 24);
}

RgbaImage blankHeatmap(uint32_t w, uint32_t h)
{
    RgbaImage img;
    img.width = w;
    img.height = h;
    img.pixels.assign(size_t(w) * h, heat(0.0));
    return img;
}

// |a - b|, with NaN against NaN equal and NaN against a number infinitely far (so it is never hidden).
double floatDiff(float a, float b)
{
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0.0 : INFINITY;
    return std::abs(double(a) - double(b));
}

// Checks that each surface group either is absent or has one value per pixel in every channel, so the
// comparison never reads past a plane that a caller filled by hand.
Status checkSurfaceSizes(const AovImage& aov, const char* which)
{
    size_t n = size_t(aov.width) * aov.height;
    auto bad = [&](bool has, std::initializer_list<const std::vector<float>*> planes) {
        if (!has) return false;
        for (const std::vector<float>* p : planes)
            if (p->size() != n) return true;
        return false;
    };
    if (bad(aov.hasBary(), {&aov.baryU, &aov.baryV}) || bad(aov.hasUv(), {&aov.uvU, &aov.uvV}) ||
        bad(aov.hasNormal(), {&aov.normalX, &aov.normalY, &aov.normalZ}))
        return makeError(ExitCode::Usage, "AOV {} has surface channels of the wrong size for {}x{}", which,
                         aov.width, aov.height);
    return okStatus();
}

}  // namespace

Result<CompareReport> compareColor(const RgbaImage& a, const RgbaImage& b, const CompareTolerance& tol)
{
    if (a.width != b.width || a.height != b.height)
        return makeError(ExitCode::Usage, "images differ in size: {}x{} vs {}x{}", a.width, a.height, b.width,
                         b.height);
    CompareReport r;
    r.width = a.width;
    r.height = a.height;
    r.heatmap = blankHeatmap(a.width, a.height);
    double sum = 0.0, sumSq = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        int worst = 0;
        for (int c = 0; c < 3; ++c) {
            int d = std::abs(int((a.pixels[i] >> (8 * c)) & 255u) - int((b.pixels[i] >> (8 * c)) & 255u));
            sum += d;
            sumSq += double(d) * d;
            worst = std::max(worst, d);
        }
        if (worst > r.maxError) {
            r.maxError = worst;
            r.maxX = uint32_t(i % a.width);
            r.maxY = uint32_t(i / a.width);
        }
        if (worst > tol.colorLsb) ++r.pixelsOverTolerance;
        r.heatmap.pixels[i] = heat(worst / 32.0);
    }
    double n = 3.0 * double(a.pixels.size());
    r.meanError = n > 0 ? sum / n : 0.0;
    r.rmsError = n > 0 ? std::sqrt(sumSq / n) : 0.0;
    r.psnr = r.rmsError > 0 ? 20.0 * std::log10(255.0 / r.rmsError) : INFINITY;
    r.pass = withinFraction(r.pixelsOverTolerance, a.pixels.size(), tol.maxFraction);
    return r;
}

Result<CompareReport> compareAov(const AovImage& a, const AovImage& b, const CompareTolerance& tol)
{
    if (a.width != b.width || a.height != b.height)
        return makeError(ExitCode::Usage, "AOVs differ in size: {}x{} vs {}x{}", a.width, a.height, b.width,
                         b.height);
    CompareReport r;
    r.isAov = true;
    r.width = a.width;
    r.height = a.height;
    r.heatmap = blankHeatmap(a.width, a.height);
    double depthSum = 0.0;
    uint64_t both = 0;
    for (size_t i = 0; i < a.id.size(); ++i) {
        bool ca = a.id[i] != 0xFFFFFFFFu, cb = b.id[i] != 0xFFFFFFFFu;
        if (ca != cb) {
            ++r.coverageMismatches;
            r.heatmap.pixels[i] = heat(1.0);
            continue;
        }
        if (!ca) continue;
        if (a.id[i] != b.id[i]) {
            ++r.idMismatches;
            r.heatmap.pixels[i] = heat(0.66);
        }
        double d = std::abs(double(a.depth[i]) - double(b.depth[i]));
        if (d > r.maxDepthDiff) {
            r.maxDepthDiff = d;
            r.maxX = uint32_t(i % a.width);
            r.maxY = uint32_t(i / a.width);
        }
        if (d > tol.depthTolerance) ++r.pixelsOverTolerance;
        if (d > 0 && a.id[i] == b.id[i]) r.heatmap.pixels[i] = heat(0.33);
        depthSum += d;
        ++both;
    }
    r.meanDepthDiff = both ? depthSum / double(both) : 0.0;

    // Surface channels: only where both images have the group (older files and renders without
    // --aov have none), and only on pixels showing the same triangle, where they mean the same thing.
    SR_TRY(checkSurfaceSizes(a, "a"));
    SR_TRY(checkSurfaceSizes(b, "b"));
    std::vector<double> surfaceWorst(a.id.size(), 0.0);
    auto compareGroup =
        [&](bool has, double& maxDiff,
            std::initializer_list<std::pair<const std::vector<float>*, const std::vector<float>*>> planes) {
            if (!has) return;
            maxDiff = 0.0;
            for (size_t i = 0; i < a.id.size(); ++i) {
                if (a.id[i] == 0xFFFFFFFFu || a.id[i] != b.id[i]) continue;
                for (auto [pa, pb] : planes) {
                    double d = floatDiff((*pa)[i], (*pb)[i]);
                    maxDiff = std::max(maxDiff, d);
                    surfaceWorst[i] = std::max(surfaceWorst[i], d);
                }
            }
        };
    compareGroup(a.hasBary() && b.hasBary(), r.maxBaryDiff, {{&a.baryU, &b.baryU}, {&a.baryV, &b.baryV}});
    compareGroup(a.hasUv() && b.hasUv(), r.maxUvDiff, {{&a.uvU, &b.uvU}, {&a.uvV, &b.uvV}});
    compareGroup(a.hasNormal() && b.hasNormal(), r.maxNormalDiff,
                 {{&a.normalX, &b.normalX}, {&a.normalY, &b.normalY}, {&a.normalZ, &b.normalZ}});
    if (a.hasAo() && b.hasAo() && a.ao.size() == a.id.size() && b.ao.size() == b.id.size()) {
        r.maxAoDiff = 0.0;
        for (size_t i = 0; i < a.id.size(); ++i)
            if (a.id[i] != 0xFFFFFFFFu && a.id[i] == b.id[i])
                r.maxAoDiff = std::max(r.maxAoDiff, floatDiff(a.ao[i], b.ao[i]));
    }
    if (tol.surfaceTolerance >= 0.0) {
        for (size_t i = 0; i < surfaceWorst.size(); ++i) {
            if (surfaceWorst[i] <= tol.surfaceTolerance) continue;
            ++r.surfaceOverTolerance;
            if (r.heatmap.pixels[i] == heat(0.0)) r.heatmap.pixels[i] = heat(0.33);
        }
    }

    // Sample channels (--aov-samples): every sample of every pixel, with the id and depth criteria.
    if (a.sampleId.size() != b.sampleId.size())
        return makeError(ExitCode::Usage, "AOVs differ in samples per pixel: {} vs {}", a.sampleId.size(),
                         b.sampleId.size());
    r.samplesPerPixel = uint32_t(a.sampleId.size());
    for (size_t k = 0; k < a.sampleId.size(); ++k) {
        const size_t n = size_t(a.width) * a.height;
        if (a.sampleId[k].size() != n || b.sampleId[k].size() != n || a.sampleDepth[k].size() != n ||
            b.sampleDepth[k].size() != n)
            return makeError(ExitCode::Usage, "AOV sample channel {} has the wrong size for {}x{}", k,
                             a.width, a.height);
        for (size_t i = 0; i < n; ++i) {
            if (a.sampleId[k][i] != b.sampleId[k][i]) {
                ++r.sampleIdMismatches;
                r.heatmap.pixels[i] = heat(0.66);
            } else if (a.sampleId[k][i] != 0xFFFFFFFFu &&
                       floatDiff(a.sampleDepth[k][i], b.sampleDepth[k][i]) > tol.depthTolerance) {
                ++r.sampleDepthOverTolerance;
                if (r.heatmap.pixels[i] == heat(0.0)) r.heatmap.pixels[i] = heat(0.33);
            }
        }
    }

    const uint64_t pixels = uint64_t(a.width) * a.height;
    r.pass = r.coverageMismatches + r.idMismatches <= tol.maxIdMismatches &&
             withinFraction(r.pixelsOverTolerance, pixels, tol.maxFraction) &&
             withinFraction(r.surfaceOverTolerance, pixels, tol.maxFraction) &&
             r.sampleIdMismatches <= tol.maxIdMismatches &&
             withinFraction(r.sampleDepthOverTolerance, pixels * r.samplesPerPixel, tol.maxFraction);
    return r;
}

PairTolerance documentedTolerance(const ImageOrigin& a, const ImageOrigin& b, bool aov)
{
    const std::string where = "docs/validation.md, \"What raster compare applies\"";
    PairTolerance p;
    if (a.backend.empty() || b.backend.empty()) {
        p.rule = "exact: a file names no backend (the default before outputs recorded theirs)";
        return p;
    }
    const std::string pair = fmt::format("{} vs {}", a.backend, b.backend);
    if (a.backend == b.backend && !a.device.empty() && a.device == b.device) {
        p.rule =
            fmt::format("exact: {} on one device ({}) is deterministic ({})", a.backend, a.device, where);
        return p;
    }
    if (isCompute(a.backend) && isCompute(b.backend)) {
        p.tolerance.colorLsb = 1;
        p.rule =
            fmt::format("{}: ids, coverage and depth exact, colour within 1/255, the goldens' criterion ({})",
                        pair, where);
        return p;
    }
    const bool graphicsPair = (isCompute(a.backend) && b.backend == "vulkan-graphics") ||
                              (a.backend == "vulkan-graphics" && isCompute(b.backend));
    if (graphicsPair && aov) {
        p.tolerance.maxIdMismatches = kGraphicsIdMismatches;
        p.tolerance.depthTolerance = kGraphicsDepthTolerance;
        p.tolerance.maxFraction = kGraphicsDepthFraction;
        p.rule = fmt::format(
            "{}: at most {} pixels (and samples) differ in id or coverage, depth within {:g} on "
            "all but {:g}% of the pixels, the oracle tests' bounds ({})",
            pair, kGraphicsIdMismatches, kGraphicsDepthTolerance, 100.0 * kGraphicsDepthFraction, where);
        return p;
    }
    if (graphicsPair) {
        p.tolerance.colorLsb = kGraphicsColorLsb;
        p.tolerance.maxFraction = kGraphicsColorFraction;
        p.rule = fmt::format(
            "{}: colour within {}/255 on all but {:g}% of the pixels (texture filtering and edges differ "
            "where the bound is not a colour; {})",
            pair, kGraphicsColorLsb, 100.0 * kGraphicsColorFraction, where);
        return p;
    }
    p.rule = fmt::format("exact: no bound is documented for {}", pair);
    return p;
}

Result<FileOrigin> fileOrigin(const std::string& path)
{
    auto own = isExrPath(path) ? readExrOrigin(path) : readPngOrigin(path);
    if (!own) return own.error();
    if (!own->backend.empty()) return FileOrigin{*own, "its metadata"};
    // A JSON of the same stem that names a backend: the goldens' provenance, --stats or a viewer save.
    const std::string sidecar = std::filesystem::path(path).replace_extension(".json").string();
    std::ifstream in(sidecar);
    if (!in) return FileOrigin{};
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
    if (json.is_discarded() || !json.is_object() || !json.contains("backend") || !json["backend"].is_string())
        return FileOrigin{};
    FileOrigin f;
    f.origin.backend = json["backend"].get<std::string>();
    if (json.contains("device") && json["device"].is_string())
        f.origin.device = json["device"].get<std::string>();
    f.source = "'" + sidecar + "'";
    return f;
}

bool isExrPath(const std::string& path)
{
    return endsWith(path, ".exr");
}

Result<CompareReport> compareFiles(const std::string& a, const std::string& b, const CompareTolerance& tol)
{
    if (isExrPath(a) != isExrPath(b))
        return makeError(ExitCode::Usage, "cannot compare '{}' with '{}': one is an EXR AOV, one is not", a,
                         b);
    if (isExrPath(a)) {
        auto ia = readAovExr(a);
        if (!ia) return ia.error();
        auto ib = readAovExr(b);
        if (!ib) return ib.error();
        return compareAov(*ia, *ib, tol);
    }
    auto ia = readPng(a);
    if (!ia) return ia.error();
    auto ib = readPng(b);
    if (!ib) return ib.error();
    return compareColor(*ia, *ib, tol);
}

std::string formatReport(const CompareReport& r, const CompareTolerance& tol)
{
    std::string s;
    uint64_t pixels = uint64_t(r.width) * r.height;
    auto pct = [&](uint64_t n) { return pixels ? 100.0 * double(n) / double(pixels) : 0.0; };
    // ", N allowed (F%)" where a fraction of the pixels may exceed a tolerance.
    auto allowed = [&](uint64_t total) {
        if (tol.maxFraction <= 0.0) return std::string();
        return fmt::format(", {} allowed ({:g}%)", uint64_t(std::floor(tol.maxFraction * double(total))),
                           100.0 * tol.maxFraction);
    };
    if (r.isAov) {
        s += fmt::format("  Coverage mismatches: {} ({:.4f}%)\n", r.coverageMismatches,
                         pct(r.coverageMismatches));
        s += fmt::format("  Id mismatches: {} ({:.4f}%), allowed {} together with coverage\n", r.idMismatches,
                         pct(r.idMismatches), tol.maxIdMismatches);
        s += fmt::format("  Max depth diff: {:.9g} @ ({}, {})\n", r.maxDepthDiff, r.maxX, r.maxY);
        s += fmt::format("  Mean depth diff: {:.9g}\n", r.meanDepthDiff);
        s += fmt::format("  {} pixels ({:.4f}%) over depth tolerance {:g}{}\n", r.pixelsOverTolerance,
                         pct(r.pixelsOverTolerance), tol.depthTolerance, allowed(pixels));
        // Printed only for groups both files have, so reports on id/Z-only files read as before.
        for (auto [label, diff] : {std::pair<const char*, double>{"bary", r.maxBaryDiff},
                                   {"uv", r.maxUvDiff},
                                   {"N", r.maxNormalDiff}}) {
            if (diff >= 0.0) s += fmt::format("  Max {} diff: {:.9g}\n", label, diff);
        }
        if (r.maxAoDiff >= 0.0) s += fmt::format("  Max ao diff: {:.9g}\n", r.maxAoDiff);
        if (r.maxBaryDiff >= 0.0 || r.maxUvDiff >= 0.0 || r.maxNormalDiff >= 0.0)
            s +=
                "  (bary, uv and N are computed on the host from the ids, by the same code for every backend:"
                " where the ids match they match by construction and prove nothing more)\n";
        if (tol.surfaceTolerance >= 0.0)
            s += fmt::format("  {} pixels ({:.4f}%) over surface tolerance {:g}{}\n", r.surfaceOverTolerance,
                             pct(r.surfaceOverTolerance), tol.surfaceTolerance, allowed(pixels));
        if (r.samplesPerPixel > 0)
            s += fmt::format(
                "  Samples ({} per pixel): {} differ in id or coverage, {} over depth tolerance{}\n",
                r.samplesPerPixel, r.sampleIdMismatches, r.sampleDepthOverTolerance,
                allowed(pixels * r.samplesPerPixel));
    } else {
        s += fmt::format("  Mean error = {:.6f} (8-bit units)\n", r.meanError);
        s += fmt::format("  RMS error = {:.6f}\n", r.rmsError);
        s += fmt::format("  Peak SNR = {:.3f} dB\n", r.psnr);
        s += fmt::format("  Max error = {} @ ({}, {})\n", r.maxError, r.maxX, r.maxY);
        s += fmt::format("  {} pixels ({:.4f}%) over {}{}\n", r.pixelsOverTolerance,
                         pct(r.pixelsOverTolerance), tol.colorLsb, allowed(pixels));
    }
    s += r.pass ? "PASS\n" : "FAILURE\n";
    return s;
}

}  // namespace sr
