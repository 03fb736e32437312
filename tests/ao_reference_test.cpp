// ao_reference_test.cpp - the ground-truth ambient occlusion (host/ao/ao_reference.h) against closed
// forms, with the radius beyond the occluders (issue 30):
//   a plane alone: 1;
//   a floor point at distance d from a step of height H (an infinitely long wall; a ray that clears
//   its top edge clears the plateau behind it too): 1/2 (1 + d / sqrt(d^2 + H^2)), which tends to 1/2
//   next to an infinitely high wall;
//   a floor point under a sphere of radius r centred at height h: 1 - (r/h)^2 (the cosine-weighted
//   measure of a cone of half-angle asin(r/h) about the normal is sin^2 of that angle).
// And what the radius means: an occluder beyond it does not occlude; a point inside a closed box sees
// nothing. The estimate is stratified over 64 x 64 rays, so it is within a few thousandths.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ao/ao_reference.h"
#include "scene/scene.h"

namespace sr::test {
namespace {

constexpr uint32_t kSide = 64;        // 4096 rays
constexpr double kTolerance = 0.004;  // stratified estimate against the closed form
constexpr double kBias = 1e-6;

// Appends the quad p0 p1 p2 p3 (two triangles) to `scene`.
void addQuad(Scene& scene, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
             const glm::dvec3& p3)
{
    const auto base = uint32_t(scene.positions.size());
    for (const glm::dvec3& p : {p0, p1, p2, p3}) scene.positions.push_back(glm::vec4(glm::vec3(p), 1.0f));
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) scene.indices.push_back(base + i);
}

// The floor z = 0, `half` units from the origin each way.
void addFloor(Scene& scene, double half)
{
    addQuad(scene, {-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0});
}

// A UV sphere of `rings` x 2 `rings` quads, radius r about c, its vertices on the sphere.
void addSphere(Scene& scene, const glm::dvec3& c, double r, int rings)
{
    auto at = [&](int i, int j) {
        const double theta = M_PI * i / rings, phi = M_PI * j / rings;
        return c + r * glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                  std::cos(theta));
    };
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < 2 * rings; ++j)
            addQuad(scene, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
}

double aoAtOrigin(const Scene& scene, double radius)
{
    const AoBvh bvh(scene);
    return referenceAo(bvh, glm::dvec3(0.0), glm::dvec3(0, 0, 1), radius, kSide, kBias);
}

// The estimate at the origin of `scene` against its closed form, printed for the record.
void expectClosedForm(const Scene& scene, double radius, double expected, const std::string& what)
{
    const double ao = aoAtOrigin(scene, radius);
    std::printf("%s: %.4f, closed form %.4f\n", what.c_str(), ao, expected);
    EXPECT_NEAR(ao, expected, kTolerance) << what;
}

TEST(ReferenceAo, APlaneAloneIsUnoccluded)
{
    Scene scene;
    addFloor(scene, 100.0);
    EXPECT_EQ(aoAtOrigin(scene, 50.0), 1.0);
}

TEST(ReferenceAo, AStepOfHeightHAtDistanceD)
{
    for (const auto& [d, h] : std::vector<std::pair<double, double>>{{1, 1}, {1, 3}, {2, 0.5}, {0.5, 4}}) {
        Scene scene;
        addFloor(scene, 1e5);
        // The step's face x = d, 1e5 units along y each way (so that almost no ray passes its ends
        // within the radius), and its top z = h.
        addQuad(scene, {d, -1e5, 0}, {d, 1e5, 0}, {d, 1e5, h}, {d, -1e5, h});
        expectClosedForm(scene, 1e4, 0.5 * (1.0 + d / std::sqrt(d * d + h * h)),
                         "step d " + std::to_string(d) + " H " + std::to_string(h));
    }
}

TEST(ReferenceAo, NextToAnInfinitelyHighWallIsOneHalf)
{
    Scene scene;
    addFloor(scene, 1e6);
    addQuad(scene, {0.01, -1e6, 0}, {0.01, 1e6, 0}, {0.01, 1e6, 1e6}, {0.01, -1e6, 1e6});
    EXPECT_NEAR(aoAtOrigin(scene, 1e7), 0.5, kTolerance);
}

TEST(ReferenceAo, UnderASphereOfRadiusRAtHeightH)
{
    for (const auto& [r, h] : std::vector<std::pair<double, double>>{{1, 2}, {1, 4}, {0.5, 0.75}}) {
        Scene scene;
        addFloor(scene, 100.0);
        addSphere(scene, {0, 0, h}, r, 96);
        expectClosedForm(scene, 50.0, 1.0 - (r / h) * (r / h),
                         "sphere r " + std::to_string(r) + " h " + std::to_string(h));
    }
}

TEST(ReferenceAo, OccludersBeyondTheRadiusDoNotOccludeAndAClosedBoxDoes)
{
    Scene sphere;
    addFloor(sphere, 100.0);
    addSphere(sphere, {0, 0, 4}, 1.0, 48);
    EXPECT_EQ(aoAtOrigin(sphere, 2.9), 1.0);  // the sphere's nearest point is 3 away
    EXPECT_LT(aoAtOrigin(sphere, 3.5), 1.0);

    Scene box;
    addFloor(box, 1.0);
    addQuad(box, {-1, -1, 2}, {1, -1, 2}, {1, 1, 2}, {-1, 1, 2});
    addQuad(box, {-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2});
    addQuad(box, {1, -1, 0}, {1, 1, 0}, {1, 1, 2}, {1, -1, 2});
    addQuad(box, {-1, -1, 0}, {1, -1, 0}, {1, -1, 2}, {-1, -1, 2});
    addQuad(box, {-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2});
    EXPECT_EQ(aoAtOrigin(box, 10.0), 0.0);
}

TEST(ReferenceAo, TheSamePointGetsTheSameRaysAndBadTrianglesAreLeftOut)
{
    Scene scene;
    addFloor(scene, 100.0);
    addSphere(scene, {0, 0, 2}, 1.0, 48);
    const double once = aoAtOrigin(scene, 50.0);
    EXPECT_EQ(aoAtOrigin(scene, 50.0), once);
    const size_t triangles = scene.indices.size() / 3;
    // A triangle with a corner that is not finite and one with an index out of range are not in the BVH.
    scene.positions.push_back(glm::vec4(NAN, 0, 0, 1));
    const auto nan = uint32_t(scene.positions.size() - 1);
    scene.indices.insert(scene.indices.end(), {0u, 1u, nan, 0u, 1u, 1000000u});
    const AoBvh bvh(scene);
    EXPECT_EQ(bvh.triangleCount(), triangles);
    EXPECT_EQ(referenceAo(bvh, glm::dvec3(0.0), glm::dvec3(0, 0, 1), 50.0, kSide, kBias), once);
}

}  // namespace
}  // namespace sr::test
