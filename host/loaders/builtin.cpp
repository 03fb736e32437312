// builtin.cpp - the procedural scene drawn when no file is given.
//
// A 4 x 4 ground plane at y = 0 carrying a UV sphere, a cube and a torus, each with its own colour:
// about 2,900 triangles, smooth normals on the curved solids, one normal per face on the flat ones.
// Every surface is a grid of (u, v) samples emitted so that dP/du x dP/dv points outwards, which
// makes all triangles counter-clockwise seen from outside (glTF's front faces).
#include <algorithm>
#include <cmath>

#include "scene/scene.h"
#include "scene/texture.h"

namespace sr {
namespace {

constexpr float kPi = 3.14159265358979f;

struct SurfacePoint {
    glm::vec3 position;
    glm::vec3 normal;
};

// Appends a (uSteps x vSteps)-cell grid of f(u, v), u and v in [0, 1]. Cells are split along the
// same diagonal; triangles that collapse to a point (the poles of the sphere) are left out.
template <typename Surface>
void addGrid(Scene& scene, int uSteps, int vSteps, const glm::vec4& color, Surface f)
{
    auto base = uint32_t(scene.positions.size());
    for (int i = 0; i <= uSteps; ++i) {
        for (int j = 0; j <= vSteps; ++j) {
            SurfacePoint s = f(float(i) / float(uSteps), float(j) / float(vSteps));
            scene.positions.emplace_back(s.position, 1.0f);
            scene.normals.emplace_back(glm::normalize(s.normal), 0.0f);
            scene.colors.push_back(color);
        }
    }
    auto at = [&](int i, int j) { return base + uint32_t(i * (vSteps + 1) + j); };
    auto addTriangle = [&](uint32_t a, uint32_t b, uint32_t c) {
        glm::vec3 pa(scene.positions[a]), pb(scene.positions[b]), pc(scene.positions[c]);
        if (pa == pb || pb == pc || pc == pa) return;
        scene.indices.insert(scene.indices.end(), {a, b, c});
    };
    for (int i = 0; i < uSteps; ++i) {
        for (int j = 0; j < vSteps; ++j) {
            // (a, b, c) and (b, d, c) both have the orientation of du x dv.
            uint32_t a = at(i, j), b = at(i + 1, j), c = at(i, j + 1), d = at(i + 1, j + 1);
            addTriangle(a, b, c);
            addTriangle(b, d, c);
        }
    }
}

// Maps the last sample of a periodic parameter onto the first, so that closed seams are exact.
float wrap(float t)
{
    return t >= 1.0f ? 0.0f : t;
}

// Rotation about +y, used to turn the cube so that no face is parallel to the default view.
glm::vec3 rotateY(const glm::vec3& v, float angle)
{
    float c = std::cos(angle), s = std::sin(angle);
    return {c * v.x + s * v.z, v.y, -s * v.x + c * v.z};
}

void addGround(Scene& scene, float half, int steps)
{
    // u runs along +z and v along +x, so du x dv = +y.
    addGrid(scene, steps, steps, glm::vec4(0.55f, 0.55f, 0.5f, 1.0f), [=](float u, float v) {
        return SurfacePoint{{-half + 2.0f * half * v, 0.0f, -half + 2.0f * half * u}, {0.0f, 1.0f, 0.0f}};
    });
}

void addSphere(Scene& scene, const glm::vec3& center, float radius, int rings = 16)
{
    // u is the polar angle from +y (pole to pole), v the azimuth: du x dv points outwards.
    addGrid(scene, rings, 2 * rings, glm::vec4(0.8f, 0.2f, 0.15f, 1.0f), [=](float u, float v) {
        // Poles and the seam are set exactly, so the pole triangles collapse (and are left out)
        // and the seam vertices coincide bit for bit: no cracks.
        float theta = u * kPi, phi = wrap(v) * 2.0f * kPi;
        float sinTheta = u <= 0.0f || u >= 1.0f ? 0.0f : std::sin(theta);
        float cosTheta = u <= 0.0f ? 1.0f : u >= 1.0f ? -1.0f : std::cos(theta);
        glm::vec3 n(sinTheta * std::sin(phi), cosTheta, sinTheta * std::cos(phi));
        return SurfacePoint{center + radius * n, n};
    });
}

// A box of half extents `half` about `center`, turned by `yaw` about +y, a quad per face.
void addBox(Scene& scene, const glm::vec3& center, const glm::vec3& half, float yaw, const glm::vec4& color)
{
    // Per face: the outward normal and two tangents s, t with s x t = normal.
    const glm::vec3 faces[6][3] = {
        {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}},
    };
    for (const auto& face : faces) {
        glm::vec3 n = face[0], s = face[1], t = face[2];
        addGrid(scene, 1, 1, color, [=](float u, float v) {
            glm::vec3 local = half * (n + (2.0f * u - 1.0f) * s + (2.0f * v - 1.0f) * t);
            return SurfacePoint{center + rotateY(local, yaw), rotateY(n, yaw)};
        });
    }
}

void addCube(Scene& scene, const glm::vec3& center, float half, float yaw)
{
    addBox(scene, center, glm::vec3(half), yaw, glm::vec4(0.2f, 0.35f, 0.8f, 1.0f));
}

void addTorus(Scene& scene, const glm::vec3& center, float major, float minor, int ring = 48, int tube = 20)
{
    // Lying flat around +y: u goes round the ring, v round the tube; du x dv points outwards.
    addGrid(scene, ring, tube, glm::vec4(0.9f, 0.7f, 0.2f, 1.0f), [=](float u, float v) {
        float a = wrap(u) * 2.0f * kPi, b = wrap(v) * 2.0f * kPi;
        glm::vec3 ring(std::sin(a), 0.0f, std::cos(a));
        glm::vec3 n = std::cos(b) * ring + glm::vec3(0.0f, std::sin(b), 0.0f);
        return SurfacePoint{center + major * ring + minor * n, n};
    });
}

void addObjects(Scene& scene)
{
    addSphere(scene, {-0.9f, 0.6f, -0.4f}, 0.6f);
    addCube(scene, {0.9f, 0.4f, -0.7f}, 0.4f, 0.5f);
    addTorus(scene, {0.4f, 0.2f, 0.9f}, 0.55f, 0.2f);
}

Scene finalized(Scene scene, const char* what);

// A quad (two triangles, counter-clockwise seen from +normal) with texture coordinates (0, 0) at
// corner a to (uvMax, uvMax) at corner c, drawn with material `material`.
void addTexturedQuad(Scene& scene, const glm::vec3 (&corner)[4], float uvMax, uint32_t material)
{
    auto base = uint32_t(scene.positions.size());
    glm::vec3 n = glm::normalize(glm::cross(corner[1] - corner[0], corner[3] - corner[0]));
    const glm::vec2 uv[4] = {{0.0f, 0.0f}, {uvMax, 0.0f}, {uvMax, uvMax}, {0.0f, uvMax}};
    for (int k = 0; k < 4; ++k) {
        scene.positions.emplace_back(corner[k], 1.0f);
        scene.normals.emplace_back(n, 0.0f);
        scene.texcoords.emplace_back(uv[k].x, uv[k].y, 0.0f, 0.0f);
    }
    scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    scene.triMaterials.insert(scene.triMaterials.end(), {material, material});
}

// A size x size RGBA8 checkerboard of `cells` x `cells` squares, colours a and b.
std::vector<uint8_t> checkerTexels(int size, int cells, glm::u8vec4 a, glm::u8vec4 b)
{
    std::vector<uint8_t> texels;
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            glm::u8vec4 c = ((x * cells / size) + (y * cells / size)) % 2 ? b : a;
            texels.insert(texels.end(), {c.x, c.y, c.z, c.w});
        }
    }
    return texels;
}

// builtin:checker - a 20 x 20 ground plane carrying a 64 x 64 black-and-white checkerboard repeated 8
// times (64 squares a side), glTF's default sampler (repeat, trilinear). Seen at a grazing angle
// (e.g. --camera orbit:0,6,12) it shows minification, mip selection and affine vs perspective UVs.
Scene checkerScene()
{
    Scene scene;
    const glm::vec3 plane[4] = {{-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, {-10, 0, -10}};
    addTexturedQuad(scene, plane, 8.0f, 0);
    std::vector<uint8_t> texels = checkerTexels(64, 8, {255, 255, 255, 255}, {0, 0, 0, 255});
    auto texture = makeTexture("checkerboard", 64, 64, texels.data(), true, TextureSampler{});
    scene.textures.push_back(std::move(*texture));
    SceneMaterial m;
    m.name = "checker";
    m.baseColorTexture = 0;
    scene.materials.push_back(m);
    return finalized(std::move(scene), "built-in checker scene");
}

// builtin:cutout - a quad whose texture is opaque orange in a checkerboard of 4 x 4 squares and
// transparent (alpha 0) in the others, alphaMode MASK, 1 unit in front of a blue quad: through each
// transparent square the blue quad must show, in the colour image and in the id and depth AOVs.
Scene cutoutScene()
{
    Scene scene;
    const glm::vec3 front[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    const glm::vec3 back[4] = {{-1.5f, -1.5f, -1}, {1.5f, -1.5f, -1}, {1.5f, 1.5f, -1}, {-1.5f, 1.5f, -1}};
    addTexturedQuad(scene, front, 1.0f, 0);
    addTexturedQuad(scene, back, 1.0f, 1);
    std::vector<uint8_t> texels = checkerTexels(16, 4, {255, 140, 20, 255}, {255, 255, 255, 0});
    TextureSampler nearest;
    nearest.magFilter = nearest.minFilter = FILTER_NEAREST;
    nearest.mipmapMode = MIPMAP_NONE;
    auto texture = makeTexture("cutout", 16, 16, texels.data(), true, nearest);
    scene.textures.push_back(std::move(*texture));
    SceneMaterial cut;
    cut.name = "cutout";
    cut.baseColorTexture = 0;
    cut.alphaMode = ALPHA_MASK;
    SceneMaterial blue;
    blue.name = "blue";
    blue.baseColorFactor = glm::vec4(0.1f, 0.25f, 0.9f, 1.0f);
    scene.materials.insert(scene.materials.end(), {cut, blue});
    scene.triFlags.assign(scene.triangleCount(), 0u);
    scene.triFlags[0] = scene.triFlags[1] = TRI_FLAG_ALPHA_MASK;
    return finalized(std::move(scene), "built-in cutout scene");
}

// The geometry built here is finite and indexed consistently, so finalizing cannot fail; it still runs
// to fill the flags and bounds the same way every loader does.
Scene finalized(Scene scene, const char* what)
{
    Status status = finalizeScene(scene, what);
    (void)status;
    return scene;
}

}  // namespace

Scene builtinScene()
{
    Scene scene;
    addGround(scene, 2.0f, 4);
    addObjects(scene);
    return finalized(std::move(scene), "built-in scene");
}

Scene aoStressScene()
{
    Scene scene;
    addGround(scene, 3.0f, 8);
    const glm::vec4 grey(0.7f, 0.7f, 0.7f, 1.0f);
    addBox(scene, {-1.0f, 0.4f, 0.0f}, {0.5f, 0.4f, 0.01f}, 0.0f,
           grey);  // a thin plate standing on the floor
    addBox(scene, {0.3f, 0.75f, 0.8f}, {0.04f, 0.75f, 0.04f}, 0.0f, grey);  // a thin post
    addBox(scene, {1.1f, 0.9f, -0.6f}, {0.35f, 0.35f, 0.35f}, 0.0f, grey);  // a box floating above the floor
    addBox(scene, {-0.2f, 0.15f, -1.2f}, {0.6f, 0.15f, 0.3f}, 0.0f, grey);  // a low step
    return finalized(std::move(scene), "built-in ambient occlusion stress scene");
}

Scene tessellatedSphere(int rings)
{
    Scene scene;
    addSphere(scene, {0.0f, 0.0f, 0.0f}, 1.0f, rings);
    return finalized(std::move(scene), "tessellated sphere");
}

Scene lowPolyScene()
{
    Scene scene;
    addGround(scene, 2.0f, 4);
    addSphere(scene, {-0.9f, 0.6f, -0.4f}, 0.6f, 4);
    addCube(scene, {0.9f, 0.4f, -0.7f}, 0.4f, 0.5f);
    addTorus(scene, {0.4f, 0.2f, 0.9f}, 0.55f, 0.2f, 12, 6);
    return finalized(std::move(scene), "built-in low-poly scene");
}

Result<Scene> builtinSceneNamed(const std::string& name)
{
    if (name == "builtin") return builtinScene();
    Scene scene;
    if (name == "builtin:dense") return tessellatedSphere(128);  // 128 x 256 quads: ~65k triangles
    // builtin:dense:N, the sphere of `raster bench --dense-rings N` (about 4 N^2 triangles).
    if (name.rfind("builtin:dense:", 0) == 0) {
        const std::string digits = name.substr(14);
        const bool number =
            !digits.empty() && digits.size() <= 5 &&
            std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
        const int rings = number ? std::stoi(digits) : 0;
        if (rings < 4 || rings > kMaxSphereRings)
            return makeError(
                ExitCode::Usage,
                "builtin:dense:N needs N in 4..{} rings (4 N^2 - 4 N triangles within the 31-bit "
                "index budget), not '{}'",
                kMaxSphereRings, digits);
        return tessellatedSphere(rings);
    }
    if (name == "builtin:huge") {
        addGround(scene, 1e5f, 1);  // two triangles, each ~1e4 times the viewport from a few units away
        addObjects(scene);
        return finalized(std::move(scene), "built-in huge scene");
    }
    if (name == "builtin:checker") return checkerScene();
    if (name == "builtin:cutout") return cutoutScene();
    if (name == "builtin:lowpoly") return lowPolyScene();
    if (name == "builtin:ao") return aoStressScene();
    return makeError(
        ExitCode::Usage,
        "unknown built-in scene '{}': expected builtin, builtin:dense, builtin:dense:N, builtin:huge, "
        "builtin:checker, builtin:cutout, builtin:lowpoly or builtin:ao",
        name);
}

}  // namespace sr
