// render_settings.h - what a render is asked to do: RenderSettings, the fields the pipeline reads, and
// RenderOptions, those plus how the scene is framed and drawn. Every member a user chooses is one entry
// of the settings schema (settings/schema.h), which gives it its name, range and help; the defaults are
// the initializers below and nowhere else.
#ifndef RASTER_RENDER_SETTINGS_H
#define RASTER_RENDER_SETTINGS_H

#include <cstdint>
#include <string>

#include <glm/glm.hpp>

#include "raster_shared.h"
#include "scene/primitive_mode.h"

namespace sr {

// The line depth bias of --wireframe (RenderSettings::lineDepthBias): depth z drawn as z - b (1 - z),
// which with a perspective camera brings an edge 1/256 of its distance closer. An edge on its own
// surface then wins the depth test wherever the surface's depth moves less than that across the line's
// half width (surfaces up to about 80 degrees from facing the camera at 1080p); an edge hidden behind
// another surface stays hidden unless the two lie within 0.4% of the distance.
constexpr float kWireframeDepthBias = 1.0f / 256.0f;

// Tessellation levels when --tess-max-level is auto (the default): flat and pn edges in at most 16
// pieces, centroid split twice. kAutoTessLevel is auto in RenderOptions::tessMaxLevel.
constexpr uint32_t kDefaultTessMaxLevel = 16;
constexpr uint32_t kDefaultCentroidLevel = 2;
constexpr uint32_t kAutoTessLevel = 0xffffffffu;

// What a render downloads. All: the colour image, the id and depth AOVs (from the visibility buffer),
// the sample AOVs and hit counts where asked for. Colour: the colour image alone. None: nothing (the
// images stay on the device; statistics and timings are still filled).
enum class ImageDownload { All, Colour, None };

// RenderSettings::outputs: the images a frame downloaded with ImageDownload::All brings back.
constexpr uint32_t OUTPUT_COLOR = 1;  // RenderOutput::color
constexpr uint32_t OUTPUT_ID = 2;     // RenderOutput::aov.id
constexpr uint32_t OUTPUT_DEPTH = 4;  // RenderOutput::aov.depth
// nvdiffrast's rasterize output, (u, v, z/w, id + 1) per pixel (shared/aovs.h), computed on the device for
// RenderSession::readImage, for a frame drawn with rasterize's camera (OpenGL's depth range mapped to
// Vulkan's); not with tessellation or level of detail, whose ids are not the scene's triangles there.
constexpr uint32_t OUTPUT_RAST = 8;
constexpr uint32_t OUTPUT_IMAGES = OUTPUT_COLOR | OUTPUT_ID | OUTPUT_DEPTH;

// --clusters (RenderSettings::clusters): whether a frame's triangles go through stage clusters
// (common/shared/cluster.h) or setup. The image is the same either way; auto takes clusters where they pay
// (RenderSession::sizeFrame).
constexpr uint32_t CLUSTERS_AUTO = 0;
constexpr uint32_t CLUSTERS_ON = 1;
constexpr uint32_t CLUSTERS_OFF = 2;

// --lod (RenderSettings::lod): continuous level of detail on a cluster hierarchy (host/scene/lod.h). off
// draws the scene's triangles; on draws, of every part of a mesh, the coarsest level whose error projects
// within lodErrorPx output pixels (common/shared/cluster.h's clusterLodDrawn).
constexpr uint32_t LOD_OFF = 0;
constexpr uint32_t LOD_ON = 1;

// --ao (RenderSettings::ao; common/shared/ao.h): AO_OFF, AO_GTAO or AO_REFERENCE (raster_shared.h). The
// default radius, when --ao-radius is 0 (auto), is this fraction of the scene's bounding-sphere radius:
// large enough for a model's contact shadows on its floor and its own creases, small enough that AO
// stays local (a room-sized occluder darkens only what lies within a tenth of the scene of it).
constexpr float kAoRadiusFraction = 0.1f;
// --ao-denoise (RenderSettings::aoDenoise): whether stage ao_denoise runs.
constexpr uint32_t AO_DENOISE_OFF = 0;
constexpr uint32_t AO_DENOISE_ON = 1;

struct RenderSettings {
    uint32_t width = 512;
    uint32_t height = 512;
    uint32_t cullMode = CULL_BACK;                 // CULL_*
    uint32_t shadingMode = SHADING_BLINN_PHONG;    // SHADING_*
    glm::vec3 lightDirView{-0.35f, 0.55f, 0.75f};  // towards the light, view space (+z to the eye)
    // The light budget (shade.h's shadeLight): a white surface (albedo 1) peaks at
    // ambient + light (1 + specular) = 0.1 + 0.75 x 1.2 = 1, the display's white, where it faces the
    // light with the highlight on top; everything else stays below, so a lit surface is never clipped
    // flat. Ambient 0.1 keeps the unlit side readable (0.08 linear, sRGB 79 at the default albedo 0.8)
    // against the 0.75 of direct light; the highlight's 0.15 is what tells Phong and Blinn-Phong from
    // Lambert.
    glm::vec3 lightColor{0.75f, 0.75f, 0.75f};
    float ambient = 0.1f;
    float specular = 0.2f;  // specular strength: the highlight's peak as a fraction of the light colour
    glm::vec3 background{0.02f, 0.02f, 0.025f};  // linear RGB
    float specularPower = 32.0f;
    uint32_t warmup = 1;                  // untimed runs before the timed ones
    uint32_t repeat = 1;                  // timed runs (>= 1)
    uint32_t initialListCapacity = 0;     // 0: lists sized from the scene; tests force tiny ones
    bool countHits = false;               // debug: count covering triangles per pixel
    bool visibilityOnly = false;          // vulkan-graphics: depth + id only (the bench's hardware baseline)
    bool firstFrameSkipsBinning = false;  // tests: start as if the last frame had no big triangle
    uint32_t textureFilter = TEXTURE_FILTER_AUTO;  // TEXTURE_FILTER_*: AUTO follows each texture's sampler
    uint32_t uvInterpolation = UV_PERSPECTIVE;     // UV_PERSPECTIVE or UV_AFFINE
    bool surfaceAovs = false;  // fill RenderOutput.aov's bary, uv and N channels (fillSurfaceAovs)
    // Anti-aliasing. msaa: coverage and depth samples per pixel at Vulkan's standard sample locations
    // (1, 2, 4, 8 or 16), shaded once per pixel and triangle. ssaa: N renders N x N pixels per output
    // pixel (the raster grid is N times the resolution per side), box-filtered; both combine.
    uint32_t msaa = 1;
    uint32_t ssaa = 1;
    // Points are squares of pointSize pixels (1..MAX_POINT_SIZE) centred on their snapped vertex.
    float pointSize = 1.0f;
    // Lines are rectangles lineWidth pixels wide (1..MAX_LINE_WIDTH, multiples of 1/8) centred on the
    // snapped segment, ends cut square at the endpoints (Vulkan's rectangular lines).
    float lineWidth = 1.0f;
    // --wireframe: the depth bias of every line (RasterParams.lineDepthBias), so that edges drawn over
    // their own surface win its depth test. 0 draws lines at their exact depth.
    float lineDepthBias = 0.0f;
    bool aovSamples = false;  // fill RenderOutput.samples with every sample's id and depth
    // The rule that decides which samples a triangle covers (RASTER_*, --raster-method;
    // common/shared/methods.h): fixed8 is the conformant one, the others are there to be compared.
    uint32_t rasterMethod = RASTER_FIXED8;
    // What of the frame comes back to the host (ImageDownload): the viewer presenting from the device
    // needs nothing, through the host only the colour image.
    ImageDownload download = ImageDownload::All;
    // With ImageDownload::All, which images (OUTPUT_* bits): only those are computed for the host and
    // copied back (the AO, hit counts, every sample and the surface AOVs as their own settings ask).
    uint32_t outputs = OUTPUT_IMAGES;
    // Of those, the ones left on the device for RenderSession::readImage rather than copied into the
    // RenderOutput (OUTPUT_RAST always is).
    uint32_t keptOutputs = 0;
    // Tessellation (--tessellate, common/shared/tessellate.h): TESS_*. flat and pn split every edge into
    // pieces of at most tessEdgePx output pixels on screen, at most tessMaxLevel of them; centroid splits
    // each triangle at its centroid tessMaxLevel times. The id AOV names the scene's triangles.
    uint32_t tessellate = TESS_OFF;
    float tessEdgePx = 8.0f;
    uint32_t tessMaxLevel = kDefaultTessMaxLevel;
    // Stage clusters (CLUSTERS_*): on draws a triangle scene through it wherever it has clusters (not
    // while tessellating, and not a scene with an index out of range); off never.
    uint32_t clusters = CLUSTERS_AUTO;
    // Level of detail (LOD_*): on draws each part of a mesh at the coarsest level of its hierarchy whose
    // geometric error projects to at most lodErrorPx output pixels; the id AOV names a simplified
    // triangle by a scene triangle at its first corner. Not with tessellation or a display scene.
    uint32_t lod = LOD_OFF;
    float lodErrorPx = 0.5f;
    // Ambient occlusion (AO_*): gtao runs stages ao_gbuffer, ao and (aoDenoise) ao_denoise over the
    // visibility buffer; reference casts aoReferenceRays^2 rays per raster pixel on the host
    // (host/ao/ao_reference.h). Either scales the ambient term of the lit shading modes; SHADING_AO shows
    // it alone. aoRadius: world units, 0 = kAoRadiusFraction of the scene's bounding radius.
    uint32_t ao = AO_OFF;
    float aoRadius = 0.0f;
    // The default is the study's knee (docs/ambient-occlusion.md): with the filter, one slice per pixel
    // is already 16 directions per 4 x 4 block, and steps buy more than slices (H100, 960x540: 1 x 8
    // is as fast as 2 x 4 and 10-25% closer to the reference on every scene).
    uint32_t aoSlices = 1;
    uint32_t aoSteps = 8;
    uint32_t aoDenoise = AO_DENOISE_ON;
    uint32_t aoReferenceRays = 16;  // rays per side of the reference's stratified grid (16: 256 rays)
};

// One render as a user describes it: the pipeline's settings, the camera and model specs and how the
// scene's primitives are drawn. resolved() gives the settings the pipeline runs with.
struct RenderOptions {
    RenderSettings settings;
    std::string camera = "auto";  // `--camera` spec: auto, gltf:N or orbit:AZ,EL,DIST[,TX,TY,TZ]
    // `--model` spec (parseModelSpec, scene/camera.h): identity or translate:X,Y,Z,rotate:AX,AY,AZ,scale:S,
    // the scene moved before the camera looks at it.
    std::string model = "identity";
    PrimitiveMode primitiveMode = PrimitiveMode::Triangles;
    bool wireframe = false;  // overlay the mesh's edges (displayScene), drawn with kWireframeDepthBias
    // The tessellation level as asked for; kAutoTessLevel: the mode's default. settings.tessMaxLevel is
    // not read here: resolved() sets it from this.
    uint32_t tessMaxLevel = kAutoTessLevel;

    // `settings` with the tessellation level resolved and the wireframe's line depth bias.
    RenderSettings resolved() const
    {
        RenderSettings s = settings;
        s.tessMaxLevel = tessMaxLevel != kAutoTessLevel
                             ? tessMaxLevel
                             : (s.tessellate == TESS_CENTROID ? kDefaultCentroidLevel : kDefaultTessMaxLevel);
        if (wireframe) s.lineDepthBias = kWireframeDepthBias;
        return s;
    }
};

// The MSAA of `raster render` and `raster batch` when not told otherwise: they make pictures, and a
// picture is expected to be anti-aliased. 4 is the count every Vulkan device supports (lavapipe's
// graphics pipeline has no other), at Vulkan's standard sample locations; colour is still shaded once
// per pixel and triangle. The library and the Python module keep RenderSettings::msaa = 1: the exact,
// one-sample-per-pixel path that tests, goldens and cross-backend checks compare.
constexpr uint32_t kImageMsaa = 4;

// The options `raster render` and `raster batch` start from: the defaults above with kImageMsaa.
inline RenderOptions imageRenderOptions()
{
    RenderOptions options;
    options.settings.msaa = kImageMsaa;
    return options;
}

}  // namespace sr

#endif  // RASTER_RENDER_SETTINGS_H
