// controls.h - what the viewer's keys and mouse do, as plain transitions of a ViewerState.
//
// The window (GLFW callbacks) and the script replay (viewer/script.h) both call these functions and
// nothing else to change the state, so a replayed script exercises the live input path. The window
// turns the state into frames (frameScene, the state's settings and camera) and carries out its
// requests (quit, save, scene and backend changes), clearing each when done.
#ifndef RASTER_CONTROLS_H
#define RASTER_CONTROLS_H

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "scene/primitive_mode.h"
#include "scene/scene.h"
#include "camera/orbit.h"

namespace sr {

enum class MouseButton { Left, Right, Middle };

// Keys are the characters they type: lowercase letters and digits (the window maps its key codes, keypad
// digits included, to these); Escape is kKeyEscape.
constexpr char kKeyEscape = 27;

// The shading modes of keys 1 to 9: the lighting models first (the default, Blinn-Phong, on 1), then the
// geometry views, then the debug views. The tenth mode, mip, has no key (`--shading mip` starts with it).
constexpr std::array<uint32_t, 9> kShadingKeyModes = {
    SHADING_BLINN_PHONG, SHADING_PHONG,        SHADING_LAMBERT,   SHADING_FLAT,    SHADING_NORMALS,
    SHADING_DEPTH,       SHADING_PRIMITIVE_ID, SHADING_HIT_COUNT, SHADING_TEXCOORD};

// An anti-aliasing setting `m` steps through.
struct AaPreset {
    const char* name;
    uint32_t msaa;
    uint32_t ssaa;
};
// Off, MSAA 4x, MSAA 8x, SSAA 2x2: MSAA first since it costs memory per sample but shading per pixel,
// SSAA last since it shades 4x (and also smooths texture and shading aliasing).
constexpr std::array<AaPreset, 4> kAaPresets = {
    {{"1x", 1, 1}, {"MSAA 4x", 4, 1}, {"MSAA 8x", 8, 1}, {"SSAA 2x2", 1, 2}}};

// The model keys' steps (onKey). Translation: a tenth of the scene's bounding radius per press, in the
// view plane or along the view axis, so a key moves the model the same way on screen from any side.
// Rotation: 15 degrees of AX, AY or AZ per press (24 presses a full turn). Scale: the powers of 1.25,
// from 1.25^-31 to 1.25^31 (about 1/1000 to 1000): a press multiplies or divides by 1.25 and a result
// within 1e-5 of a power 1.25^n becomes float(1.25^n), so presses undo each other exactly (a float
// product alone would drift: 1 / 1.25 / 1.25 * 1.25 * 1.25 is not 1) and the spec stays short.
constexpr float kModelStepRadii = 0.1f;
constexpr float kModelStepDeg = 15.0f;
constexpr double kModelScaleStep = 1.25;
constexpr int kMaxModelScaleSteps = 31;

struct ViewerState {
    OrbitCamera camera;
    // The model transform (`--model`, scene/camera.h) the model keys change; the camera frames the
    // scene as loaded whatever it is.
    ModelTransform model;
    // What the next frame renders with: the window's framebuffer size, settings.shadingMode (keys 1-9),
    // msaa and ssaa (the AA preset) and lineDepthBias (the wireframe overlay) follow the controls.
    RenderSettings settings;
    // Index into kAaPresets, or -1 while the command line's own msaa / ssaa (no preset) is in use.
    int aaPreset = 0;
    bool wireframe = false;
    PrimitiveMode primitiveMode = PrimitiveMode::Triangles;
    uint32_t backendIndex = 0;  // among the window's backends (CUDA, Vulkan: those that opened)
    uint32_t backendCount = 1;

    // Requests for the window, which clears each when it has carried it out.
    bool quit = false;
    bool saveRequested = false;
    std::string savePrefix;       // the saved files' path without extension; empty: the window names them
    bool sceneChanged = false;    // wireframe or primitive mode changed: rebuild frameScene and its session
    bool backendChanged = false;  // backendIndex changed: render on that backend from now on
};

// The state the viewer starts in: `camera`, `settings` (the command line's), the overlay and mode, and
// the AA preset that matches settings.msaa and ssaa (-1 if none does).
ViewerState makeViewerState(const OrbitCamera& camera, const RenderSettings& settings, bool wireframe,
                            PrimitiveMode mode, uint32_t backendCount = 1);

// Key `key` pressed: 1-9 shading (kShadingKeyModes), m next AA preset, a ambient occlusion (GTAO) on /
// off (leaving --shading ao for the first key's mode when it goes off), w wireframe overlay on / off, p
// primitive mode triangles -> lines -> points -> triangles, b next backend (when there are several), r
// camera and model reset (the auto camera for the current size, the identity), s save, q and Escape
// quit. The model keys: j / l move the model left / right and i / k up / down in the view plane (the
// camera's right and up vectors), u / o towards / away from the camera; x / X, y / Y, z / Z add +-
// kModelStepDeg to AX, AY, AZ of the spec (kept within (-180, 180]; with M = T Rz Ry Rx S, z turns about the
// world z axis through the centre, x about the model's own x axis); + (or =) / - scale it up / down by
// kModelScaleStep. Returns false for a key with no
// binding, which changes nothing.
bool onKey(ViewerState& state, char key);
// Whether onKey binds `key`.
bool isBoundKey(char key);
// Drag by (dx, dy) window pixels (y down) with `button` held: left orbits, right and middle pan.
void onDrag(ViewerState& state, MouseButton button, float dx, float dy);
// Wheel by `steps` (positive: towards the scene, as GLFW's y offset scrolling up): zoom.
void onScroll(ViewerState& state, float steps);
// Framebuffer resized to width x height pixels. A minimized window's 0 x 0, or a side over
// MAX_FRAMEBUFFER_DIM, changes nothing and returns false.
bool onResize(ViewerState& state, uint32_t width, uint32_t height);
// A save to `prefix`.png, .exr and .json (empty: the window names them), as key s asks for one.
void requestSave(ViewerState& state, const std::string& prefix);

// The scene the state draws: `base` in its primitive mode with its wireframe overlay (displayScene, as
// `raster render --primitive-mode ... --wireframe` draws it).
Scene frameScene(const Scene& base, const ViewerState& state);

// Name of the state's AA setting: the preset's, or "MSAA Nx SSAA MxM" for the command line's own.
std::string aaName(const ViewerState& state);
// One line for the window title: shading, AA, primitive mode, wireframe, the model spec unless identity.
std::string stateSummary(const ViewerState& state);

// The controls, one per line, for `raster view --help` and docs/viewer.md.
std::string controlsHelp();

}  // namespace sr

#endif  // RASTER_CONTROLS_H
