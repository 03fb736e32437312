// fuzz_loaders.cpp - raster_fuzz: mutated scene files and images through the loaders, in process.
//
// The build uses g++, so there is no libFuzzer: this is a plain seeded mutation loop. Iteration i draws
// every choice from std::mt19937_64 seeded with (seed, i) alone, so any iteration can be replayed on
// its own with `--seed K --start I --iterations 1`. Each mutant is written into a scratch folder under
// its corpus file's name, next to copies of that file's siblings, so relative URIs (.bin, .png, .mtl)
// still resolve. A loader must return a scene or texture that keeps the invariants of scene.h, or an
// error of one line; anything else is reported on stdout, the mutant is kept under --keep, the run goes
// on and the exit status is 1. Crashes and hangs are left to the caller (ctest's timeout, an ASan/UBSan
// build); the mutant of a crash is left in the scratch folder named at the start. Loader warnings go to
// stderr as usual: hiding stderr would also hide a sanitizer's report.
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include "scene/scene.h"
#include "scene/texture.h"

namespace fs = std::filesystem;

namespace {

enum class Kind { Scene, Image };

struct CorpusFile {
    fs::path source;   // where it was read from
    fs::path scratch;  // where its mutants are written (next to copies of its siblings)
    std::string bytes;
    Kind kind = Kind::Scene;
    bool text = false;  // .gltf and .obj: number tokens are worth replacing
};

struct Options {
    std::optional<double> seconds;
    std::optional<uint64_t> iterations;
    uint64_t start = 0;
    uint64_t seed = 1;
    std::vector<fs::path> corpusDirs;
    std::optional<fs::path> keep;
};

std::optional<std::string> readFile(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool writeFile(const fs::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
}

std::optional<Kind> kindOf(const fs::path& path, bool& text)
{
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    text = ext == ".gltf" || ext == ".obj";
    if (ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".ply" || ext == ".stl")
        return Kind::Scene;
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") return Kind::Image;
    return std::nullopt;
}

// The default corpus: the project's assets and, where Debian's assimp-testmodels is installed, a
// textured glTF (text and binary), OBJ files with materials and points, the images they use, and PLY
// and STL in ASCII and binary.
std::vector<fs::path> defaultCorpus()
{
    const fs::path assimp = "/usr/share/assimp/models";
    return {
        fs::path(SR_SOURCE_DIR) / "assets/hierarchy.gltf",
        fs::path(SR_SOURCE_DIR) / "assets/shapes.obj",
        assimp / "glTF2/BoxTextured-glTF/BoxTextured.gltf",
        assimp / "glTF2/BoxTextured-glTF/CesiumLogoFlat.png",
        assimp / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb",
        assimp / "OBJ/spider.obj",
        assimp / "OBJ/testpoints.obj",
        assimp / "OBJ/SpiderTex.jpg",
        assimp / "PLY/cube.ply",
        assimp / "PLY/cube_binary.ply",
        assimp / "PLY/float-color.ply",
        assimp / "STL/triangle_with_two_solids.stl",
        assimp / "STL/Spider_binary.stl",
    };
}

// Files of --corpus folders (not recursive), in name order so the corpus order is reproducible.
std::vector<fs::path> corpusFromDirs(const std::vector<fs::path>& dirs)
{
    std::vector<fs::path> files;
    for (const fs::path& dir : dirs) {
        std::error_code ec;
        std::vector<fs::path> found;
        for (const auto& entry : fs::directory_iterator(dir, ec)) {
            bool text = false;
            if (entry.is_regular_file() && kindOf(entry.path(), text)) found.push_back(entry.path());
        }
        if (ec) fmt::print("note: cannot read corpus folder {}: {}\n", dir.string(), ec.message());
        std::sort(found.begin(), found.end());
        files.insert(files.end(), found.begin(), found.end());
    }
    return files;
}

// Reads the corpus and gives each source folder one scratch folder holding copies of all its regular
// files (small ones only: the siblings a scene refers to).
std::vector<CorpusFile> loadCorpus(const std::vector<fs::path>& paths, const fs::path& scratchRoot)
{
    std::vector<CorpusFile> corpus;
    std::vector<std::pair<fs::path, fs::path>> folders;  // source folder -> scratch folder
    for (const fs::path& path : paths) {
        bool text = false;
        std::optional<Kind> kind = kindOf(path, text);
        std::optional<std::string> bytes = kind ? readFile(path) : std::nullopt;
        if (!bytes || !fs::is_regular_file(path)) {
            fmt::print("note: skipping corpus file {} (missing or not a scene or image)\n", path.string());
            continue;
        }
        fs::path dir = path.parent_path();
        auto it = std::find_if(folders.begin(), folders.end(), [&](const auto& f) { return f.first == dir; });
        if (it == folders.end()) {
            fs::path scratchDir = scratchRoot / std::to_string(folders.size());
            fs::create_directories(scratchDir);
            std::error_code ec;
            for (const auto& entry : fs::directory_iterator(dir, ec)) {
                if (entry.is_regular_file() && entry.file_size() <= (8u << 20)) {
                    fs::copy_file(entry.path(), scratchDir / entry.path().filename(),
                                  fs::copy_options::overwrite_existing, ec);
                }
            }
            folders.emplace_back(dir, scratchDir);
            it = folders.end() - 1;
        }
        corpus.push_back({path, it->second / path.filename(), std::move(*bytes), *kind, text});
    }
    return corpus;
}

// ---- mutations -------------------------------------------------------------------------------------

using Rng = std::mt19937_64;

uint64_t below(Rng& rng, uint64_t n)
{
    return n == 0 ? 0 : std::uniform_int_distribution<uint64_t>(0, n - 1)(rng);
}

constexpr std::array<char, 18> kInterestingBytes = {'\0', '\xff', '\x7f', '\x80', '0', '1', '9', '{',  '[',
                                                    '"',  '}',    ']',    ',',    '-', '.', 'e', '\n', ' '};
constexpr std::array<const char*, 10> kNumberTokens = {
    "1e39",       "-1",          "4294967295",           "nan", "-0", "1e-45",
    "2147483648", "-2147483649", "18446744073709551616", "inf"};

// A random [begin, begin + length) inside `size` bytes, mostly short so that structure survives.
std::pair<size_t, size_t> pickRange(Rng& rng, size_t size)
{
    size_t begin = below(rng, size + 1);
    size_t maxLength = std::min<size_t>(size - begin, below(rng, 4) == 0 ? 4096 : 16);
    return {begin, below(rng, maxLength + 1)};
}

// Replaces one number of the text, picked at random (with its sign, fraction and exponent), by one of
// kNumberTokens.
void replaceNumber(Rng& rng, std::string& bytes)
{
    std::vector<std::pair<size_t, size_t>> numbers;
    for (size_t i = 0; i < bytes.size();) {
        if (std::isdigit(static_cast<unsigned char>(bytes[i]))) {
            size_t begin = (i > 0 && bytes[i - 1] == '-') ? i - 1 : i;
            while (i < bytes.size() &&
                   (std::isdigit(static_cast<unsigned char>(bytes[i])) || bytes[i] == '.' ||
                    bytes[i] == 'e' || bytes[i] == 'E' || bytes[i] == '-' || bytes[i] == '+'))
                ++i;
            numbers.emplace_back(begin, i - begin);
        } else {
            ++i;
        }
    }
    if (numbers.empty()) return;
    auto [begin, length] = numbers[below(rng, numbers.size())];
    bytes.replace(begin, length, kNumberTokens[below(rng, kNumberTokens.size())]);
}

void mutate(Rng& rng, std::string& bytes, const CorpusFile& file, const std::vector<CorpusFile>& corpus)
{
    int count = 1 + static_cast<int>(below(rng, 8));
    for (int m = 0; m < count; ++m) {
        switch (below(rng, file.text ? 9 : 8)) {
        case 0:  // flip one bit
            if (!bytes.empty()) bytes[below(rng, bytes.size())] ^= static_cast<char>(1u << below(rng, 8));
            break;
        case 1:  // overwrite a byte with an interesting value
            if (!bytes.empty())
                bytes[below(rng, bytes.size())] = kInterestingBytes[below(rng, kInterestingBytes.size())];
            break;
        case 2: {  // overwrite four bytes with a little-endian integer (GLB lengths, chunk types)
            if (bytes.size() < 4) break;
            static constexpr std::array<uint32_t, 6> kWords = {0,           1,           0x7fffffffu,
                                                               0x80000000u, 0xffffffffu, 0x10000u};
            uint32_t word = kWords[below(rng, kWords.size())];
            size_t at = below(rng, bytes.size() - 3);
            for (int b = 0; b < 4; ++b) bytes[at + b] = static_cast<char>(word >> (8 * b));
            break;
        }
        case 3: {  // insert interesting bytes
            size_t at = below(rng, bytes.size() + 1);
            std::string run(1 + below(rng, 16), kInterestingBytes[below(rng, kInterestingBytes.size())]);
            bytes.insert(at, run);
            break;
        }
        case 4: {  // delete a range
            auto [begin, length] = pickRange(rng, bytes.size());
            bytes.erase(begin, length);
            break;
        }
        case 5: {  // duplicate a range in place
            auto [begin, length] = pickRange(rng, bytes.size());
            bytes.insert(begin, bytes.substr(begin, length));
            break;
        }
        case 6: {  // splice in part of another corpus file
            const std::string& other = corpus[below(rng, corpus.size())].bytes;
            auto [begin, length] = pickRange(rng, other.size());
            size_t at = below(rng, bytes.size() + 1);
            bytes.replace(at, below(rng, 2) ? length : 0, other.substr(begin, length));
            break;
        }
        case 7:  // truncate
            bytes.resize(below(rng, bytes.size() + 1));
            break;
        case 8:  // a number token becomes huge, negative or not a number
            replaceNumber(rng, bytes);
            break;
        }
    }
}

// ---- checks ----------------------------------------------------------------------------------------

bool finite(const glm::vec4& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

// The first broken invariant of a texture (scene.h's SceneTexture), or an empty string.
std::string checkTexture(const sr::SceneTexture& t)
{
    if (t.width == 0 || t.height == 0 || t.width > MAX_TEXTURE_DIM || t.height > MAX_TEXTURE_DIM)
        return fmt::format("texture '{}' is {}x{}", t.name, t.width, t.height);
    uint32_t levels = 1;
    while ((std::max(t.width, t.height) >> levels) != 0) ++levels;
    if (t.levels != levels)
        return fmt::format("texture '{}' has {} levels, expected {}", t.name, t.levels, levels);
    size_t texels = 0;
    for (uint32_t k = 0; k < levels; ++k)
        texels += size_t(std::max(1u, t.width >> k)) * std::max(1u, t.height >> k);
    if (t.texels.size() != texels)
        return fmt::format("texture '{}' has {} texels, expected {}", t.name, t.texels.size(), texels);
    return {};
}

// The first broken invariant of a loaded scene (the contract in scene.h), or an empty string. Only
// referenced vertices must be finite: finalizeScene drops primitives, not vertices, and a dropped
// segment or point names kDroppedVertex (a dropped triangle a kept vertex, thrice).
std::string checkScene(const sr::Scene& s)
{
    size_t n = s.vertexCount();
    if (s.normals.size() != n) return fmt::format("{} normals for {} vertices", s.normals.size(), n);
    if (!s.colors.empty() && s.colors.size() != n)
        return fmt::format("{} colours for {} vertices", s.colors.size(), n);
    if (!s.texcoords.empty() && s.texcoords.size() != n)
        return fmt::format("{} texcoords for {} vertices", s.texcoords.size(), n);
    if (s.indices.size() % 3 != 0) return fmt::format("{} triangle indices", s.indices.size());
    if (s.lines.size() % 2 != 0) return fmt::format("{} line indices", s.lines.size());
    if (s.triFlags.size() != s.triangleCount())
        return fmt::format("{} flags for {} triangles", s.triFlags.size(), s.triangleCount());
    if (s.primitiveCount() == 0) return "a scene with nothing to draw";
    for (const std::vector<uint32_t>* list : {&s.indices, &s.lines, &s.points}) {
        for (uint32_t v : *list) {
            if (v == sr::kDroppedVertex && list != &s.indices) continue;
            if (v >= n) return fmt::format("index {} of {} vertices", v, n);
            if (!finite(s.positions[v])) return fmt::format("vertex {} is used and not finite", v);
        }
    }
    if (s.materials.empty()) {
        if (!s.triMaterials.empty() || !s.lineMaterials.empty() || !s.pointMaterials.empty())
            return "per-primitive materials without materials";
    } else {
        if (s.triMaterials.size() != s.triangleCount() || s.lineMaterials.size() != s.lineCount() ||
            s.pointMaterials.size() != s.pointCount())
            return "per-primitive material counts differ from primitive counts";
        for (const std::vector<uint32_t>* list : {&s.triMaterials, &s.lineMaterials, &s.pointMaterials})
            for (uint32_t m : *list)
                if (m >= s.materials.size()) return fmt::format("material {} of {}", m, s.materials.size());
    }
    for (const sr::SceneMaterial& m : s.materials) {
        if (m.baseColorTexture < -1 || m.baseColorTexture >= static_cast<int32_t>(s.textures.size()))
            return fmt::format("material '{}' uses texture {} of {}", m.name, m.baseColorTexture,
                               s.textures.size());
        if (m.texCoord > 1) return fmt::format("material '{}' uses texcoord set {}", m.name, m.texCoord);
    }
    for (const sr::SceneTexture& t : s.textures)
        if (std::string e = checkTexture(t); !e.empty()) return e;
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(s.boundsMin[a]) || !std::isfinite(s.boundsMax[a]) ||
            s.boundsMin[a] > s.boundsMax[a])
            return "bounds not finite or empty";
    }
    return {};
}

// Runs the loader on `path`; the first broken rule, or an empty string.
std::string loadAndCheck(const CorpusFile& file, const std::string& mutant, uint64_t& loaded)
{
    std::string path = file.scratch.string();
    auto oneLine = [](const sr::Error& e) {
        if (e.message.find('\n') == std::string::npos) return std::string();
        // Shown escaped, so that the report itself stays on one line.
        std::string shown;
        for (char c : e.message) shown += c == '\n' ? std::string("\\n") : std::string(1, c);
        return "error message has several lines: " + shown;
    };
    if (file.kind == Kind::Scene) {
        sr::Result<sr::Scene> scene = sr::loadScene(path);
        if (!scene.ok()) return oneLine(scene.error());
        ++loaded;
        return checkScene(scene.value());
    }
    // glTF reaches both entry points (image URIs and embedded or buffer-view images): try the bytes
    // through each.
    sr::Result<sr::SceneTexture> fromFile = sr::loadTextureFile(path, true, sr::TextureSampler{});
    sr::Result<sr::SceneTexture> fromMemory = sr::loadTextureMemory(
        path, reinterpret_cast<const uint8_t*>(mutant.data()), mutant.size(), true, sr::TextureSampler{});
    for (sr::Result<sr::SceneTexture>* texture : {&fromFile, &fromMemory}) {
        std::string e = texture->ok() ? checkTexture(texture->value()) : oneLine(texture->error());
        if (!e.empty()) return e;
    }
    if (fromFile.ok()) ++loaded;
    return {};
}

bool parseOptions(int argc, char** argv, Options& o)
{
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        bool hasValue = i + 1 < argc;
        try {
            if (arg == "--seconds" && hasValue) {
                o.seconds = std::stod(argv[++i]);
            } else if (arg == "--iterations" && hasValue) {
                o.iterations = std::stoull(argv[++i]);
            } else if (arg == "--start" && hasValue) {
                o.start = std::stoull(argv[++i]);
            } else if (arg == "--seed" && hasValue) {
                o.seed = std::stoull(argv[++i]);
            } else if (arg == "--keep" && hasValue) {
                o.keep = argv[++i];
            } else if (arg == "--corpus" && hasValue) {
                while (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0)
                    o.corpusDirs.push_back(argv[++i]);
            } else {
                return false;
            }
        } catch (const std::exception&) {
            return false;
        }
    }
    return true;
}

}  // namespace

int main(int argc, char** argv)
{
    Options o;
    if (!parseOptions(argc, argv, o)) {
        fmt::print(
            stderr,
            "usage: raster_fuzz [--seconds S] [--iterations N] [--start I] [--seed K] [--corpus DIR...] "
            "[--keep DIR]\n");
        return 2;
    }
    // Without a bound the run is short, so a bare `raster_fuzz` is a smoke test.
    if (!o.seconds && !o.iterations) o.iterations = 1000;

    fs::path scratchRoot = fs::temp_directory_path() / fmt::format("raster_fuzz_{}", ::getpid());
    fs::remove_all(scratchRoot);
    std::vector<CorpusFile> corpus =
        loadCorpus(o.corpusDirs.empty() ? defaultCorpus() : corpusFromDirs(o.corpusDirs), scratchRoot);
    if (corpus.empty()) {
        fmt::print(stderr, "raster_fuzz: no corpus file found\n");
        return 2;
    }
    fmt::print("raster_fuzz: {} corpus file(s), seed {}, scratch {}\n", corpus.size(), o.seed,
               scratchRoot.string());
    std::fflush(stdout);

    auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    uint64_t done = 0;
    uint64_t loaded = 0;  // mutants that still loaded: the rest were refused with an error
    int status = 0;
    uint64_t failures = 0;
    std::vector<std::pair<std::string, uint64_t>>
        signatures;  // failure kind -> times met, in first-met order
    constexpr uint64_t kShownPerSignature = 3;
    for (uint64_t i = o.start;; ++i) {
        if (o.iterations && done >= *o.iterations) break;
        if (o.seconds && elapsed() >= *o.seconds) break;
        std::seed_seq seq{static_cast<uint32_t>(o.seed), static_cast<uint32_t>(o.seed >> 32),
                          static_cast<uint32_t>(i), static_cast<uint32_t>(i >> 32)};
        Rng rng(seq);
        const CorpusFile& file = corpus[below(rng, corpus.size())];
        std::string mutant = file.bytes;
        mutate(rng, mutant, file, corpus);
        if (!writeFile(file.scratch, mutant)) {
            fmt::print("raster_fuzz: cannot write {}\n", file.scratch.string());
            status = 2;
            break;
        }
        std::string failure = loadAndCheck(file, mutant, loaded);
        // The next iteration may load this file as a sibling (a glTF's image): it must see the original.
        writeFile(file.scratch, file.bytes);
        ++done;
        if (!failure.empty()) {
            ++failures;
            // One bug tends to be met again and again: its signature is the corpus file and the failure
            // text up to the first quote (before paths and garbled bytes). The first few of each are
            // printed and kept, the rest counted, and the run goes on to look for others.
            std::string signature = file.source.filename().string() + ": " +
                                    failure.substr(0, std::min(failure.find('\''), size_t(60)));
            auto seen = std::find_if(signatures.begin(), signatures.end(),
                                     [&](const auto& entry) { return entry.first == signature; });
            if (seen == signatures.end()) seen = signatures.insert(seen, {signature, 0});
            if (++seen->second > kShownPerSignature) continue;
            fmt::print("raster_fuzz: FAILED at --seed {} --start {} ({}): {}\n", o.seed, i,
                       file.source.string(), failure);
            if (o.keep) {
                std::error_code ec;
                fs::create_directories(*o.keep, ec);
                fs::path kept =
                    *o.keep / fmt::format("seed{}-iter{}-{}", o.seed, i, file.source.filename().string());
                writeFile(kept, mutant);
                fmt::print("raster_fuzz: mutant kept as {}\n", kept.string());
            }
            std::fflush(stdout);
        }
    }
    double seconds = elapsed();
    fmt::print("raster_fuzz: {} iteration(s) in {:.1f} s ({:.0f}/s), {} loaded, {} refused, {}\n", done,
               seconds, seconds > 0 ? done / seconds : 0.0, loaded, done - loaded,
               failures == 0 ? std::string("no failure") : fmt::format("{} failure(s)", failures));
    for (const auto& [signature, count] : signatures) fmt::print("raster_fuzz: {} x {}\n", count, signature);
    if (failures > 0 && status == 0) status = 1;
    fs::remove_all(scratchRoot);
    return status;
}
