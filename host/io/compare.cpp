// compare.cpp - see compare.h.
#include "io/compare.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

namespace sr {
namespace {

bool endsWith(const std::string& s, const std::string& suffix)
{
    if (s.size() < suffix.size()) return false;
    return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                      [](char a, char b) { return std::tolower(a) == std::tolower(b); });
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
    r.pass = r.pixelsOverTolerance == 0;
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
    r.pass = r.coverageMismatches + r.idMismatches <= tol.maxIdMismatches && r.pixelsOverTolerance == 0;
    return r;
}

Result<CompareReport> compareFiles(const std::string& a, const std::string& b, const CompareTolerance& tol)
{
    if (endsWith(a, ".exr") != endsWith(b, ".exr"))
        return makeError(ExitCode::Usage, "cannot compare '{}' with '{}': one is an EXR AOV, one is not", a,
                         b);
    if (endsWith(a, ".exr")) {
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
    if (r.isAov) {
        s += fmt::format("  Coverage mismatches: {} ({:.4f}%)\n", r.coverageMismatches,
                         pct(r.coverageMismatches));
        s += fmt::format("  Id mismatches: {} ({:.4f}%), allowed {} together with coverage\n", r.idMismatches,
                         pct(r.idMismatches), tol.maxIdMismatches);
        s += fmt::format("  Max depth diff: {:.9g} @ ({}, {})\n", r.maxDepthDiff, r.maxX, r.maxY);
        s += fmt::format("  Mean depth diff: {:.9g}\n", r.meanDepthDiff);
        s += fmt::format("  {} pixels ({:.4f}%) over depth tolerance {:g}\n", r.pixelsOverTolerance,
                         pct(r.pixelsOverTolerance), tol.depthTolerance);
    } else {
        s += fmt::format("  Mean error = {:.6f} (8-bit units)\n", r.meanError);
        s += fmt::format("  RMS error = {:.6f}\n", r.rmsError);
        s += fmt::format("  Peak SNR = {:.3f} dB\n", r.psnr);
        s += fmt::format("  Max error = {} @ ({}, {})\n", r.maxError, r.maxX, r.maxY);
        s += fmt::format("  {} pixels ({:.4f}%) over {}\n", r.pixelsOverTolerance, pct(r.pixelsOverTolerance),
                         tol.colorLsb);
    }
    s += r.pass ? "PASS\n" : "FAILURE\n";
    return s;
}

}  // namespace sr
