// controls.cpp - the viewer's key and mouse bindings as ViewerState transitions.
#include "viewer/controls.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "settings/schema.h"

namespace sr {
namespace {

void applyAaPreset(ViewerState& state, int preset)
{
    state.aaPreset = preset;
    state.settings.msaa = kAaPresets[size_t(preset)].msaa;
    state.settings.ssaa = kAaPresets[size_t(preset)].ssaa;
}

PrimitiveMode nextMode(PrimitiveMode mode)
{
    switch (mode) {
    case PrimitiveMode::Triangles: return PrimitiveMode::Lines;
    case PrimitiveMode::Lines: return PrimitiveMode::Points;
    case PrimitiveMode::Points: break;
    }
    return PrimitiveMode::Triangles;
}

// Angle `degrees` + `step` within (-180, 180]: the spec stays short, and multiples of the step stay exact.
float turn(float degrees, float step)
{
    float a = degrees + step;
    if (a > 180.0f) a -= 360.0f;
    if (a <= -180.0f) a += 360.0f;
    return a;
}

// The scale one press up (direction +1) or down (-1) from `scale` (kModelScaleStep's comment); at the
// end of the range it stays.
float scaleStep(float scale, int direction)
{
    const double next = double(scale) * std::pow(kModelScaleStep, direction);
    const double n = std::round(std::log(next) / std::log(kModelScaleStep));
    const double power = std::pow(kModelScaleStep, n);
    const double snapped = std::fabs(next - power) <= 1e-5 * power ? power : next;
    const double limit = std::pow(kModelScaleStep, kMaxModelScaleSteps) * (1.0 + 1e-5);
    if (snapped > limit || snapped < 1.0 / limit) return scale;
    return float(snapped);
}

// Model keys (onKey's comment); false for any other key.
bool onModelKey(ViewerState& state, char key)
{
    ModelTransform& m = state.model;
    const OrbitBasis basis = orbitBasis(state.camera.pose());
    const float step = kModelStepRadii * state.camera.sphere().radius;
    switch (key) {
    case 'j': m.translate -= step * basis.right; return true;
    case 'l': m.translate += step * basis.right; return true;
    case 'i': m.translate += step * basis.up; return true;
    case 'k': m.translate -= step * basis.up; return true;
    case 'u': m.translate += step * basis.back; return true;
    case 'o': m.translate -= step * basis.back; return true;
    case 'x': m.rotateDeg.x = turn(m.rotateDeg.x, kModelStepDeg); return true;
    case 'X': m.rotateDeg.x = turn(m.rotateDeg.x, -kModelStepDeg); return true;
    case 'y': m.rotateDeg.y = turn(m.rotateDeg.y, kModelStepDeg); return true;
    case 'Y': m.rotateDeg.y = turn(m.rotateDeg.y, -kModelStepDeg); return true;
    case 'z': m.rotateDeg.z = turn(m.rotateDeg.z, kModelStepDeg); return true;
    case 'Z': m.rotateDeg.z = turn(m.rotateDeg.z, -kModelStepDeg); return true;
    case '+':
    case '=': m.scale = scaleStep(m.scale, 1); return true;
    case '-': m.scale = scaleStep(m.scale, -1); return true;
    default: return false;
    }
}

}  // namespace

ViewerState makeViewerState(const OrbitCamera& camera, const RenderSettings& settings, bool wireframe,
                            PrimitiveMode mode, uint32_t backendCount)
{
    ViewerState state;
    state.camera = camera;
    state.settings = settings;
    state.wireframe = wireframe;
    state.settings.lineDepthBias = wireframe ? kWireframeDepthBias : 0.0f;
    state.primitiveMode = mode;
    state.backendCount = backendCount > 0 ? backendCount : 1;
    state.aaPreset = -1;
    for (size_t i = 0; i < kAaPresets.size(); ++i)
        if (kAaPresets[i].msaa == settings.msaa && kAaPresets[i].ssaa == settings.ssaa)
            state.aaPreset = int(i);
    return state;
}

bool isBoundKey(char key)
{
    switch (key) {
    case 'm':
    case 'a':
    case 'w':
    case 'p':
    case 'b':
    case 'r':
    case 's':
    case 'q':
    case kKeyEscape: return true;
    default:
        return (key >= '1' && key <= '9') || std::string("jlikuoxXyYzZ+=-").find(key) != std::string::npos;
    }
}

bool onKey(ViewerState& state, char key)
{
    if (key >= '1' && key <= '9') {
        state.settings.shadingMode = kShadingKeyModes[size_t(key - '1')];
        return true;
    }
    switch (key) {
    case 'm':
        // From the command line's own setting (-1) the cycle starts at the first preset.
        applyAaPreset(state, (state.aaPreset + 1) % int(kAaPresets.size()));
        return true;
    case 'a':
        // Ambient occlusion on (GTAO, the settings' radius, slices and steps) or off; from --ao reference,
        // off first.
        state.settings.ao = state.settings.ao == AO_OFF ? AO_GTAO : AO_OFF;
        if (state.settings.ao == AO_OFF && state.settings.shadingMode == SHADING_AO)
            state.settings.shadingMode = kShadingKeyModes[0];
        return true;
    case 'w':
        state.wireframe = !state.wireframe;
        state.settings.lineDepthBias = state.wireframe ? kWireframeDepthBias : 0.0f;
        state.sceneChanged = true;
        return true;
    case 'p':
        state.primitiveMode = nextMode(state.primitiveMode);
        state.sceneChanged = true;
        return true;
    case 'b':
        // With one backend there is nothing to switch to; the key is still the backend key.
        if (state.backendCount > 1) {
            state.backendIndex = (state.backendIndex + 1) % state.backendCount;
            state.backendChanged = true;
        }
        return true;
    case 'r':
        state.camera.reset(state.settings.width, state.settings.height);
        state.model = ModelTransform{};
        return true;
    case 's': requestSave(state, ""); return true;
    case 'q':
    case kKeyEscape: state.quit = true; return true;
    default: return onModelKey(state, key);
    }
}

void onDrag(ViewerState& state, MouseButton button, float dx, float dy)
{
    if (button == MouseButton::Left)
        state.camera.orbit(dx, dy);
    else
        state.camera.pan(dx, dy, state.settings.height);
}

void onScroll(ViewerState& state, float steps)
{
    state.camera.zoom(steps);
}

bool onResize(ViewerState& state, uint32_t width, uint32_t height)
{
    if (width < 1 || height < 1 || width > MAX_FRAMEBUFFER_DIM || height > MAX_FRAMEBUFFER_DIM) return false;
    state.settings.width = width;
    state.settings.height = height;
    return true;
}

void requestSave(ViewerState& state, const std::string& prefix)
{
    state.saveRequested = true;
    state.savePrefix = prefix;
}

Scene frameScene(const Scene& base, const ViewerState& state)
{
    return displayScene(base, state.primitiveMode, state.wireframe);
}

std::string aaName(const ViewerState& state)
{
    if (state.aaPreset >= 0 && size_t(state.aaPreset) < kAaPresets.size())
        return kAaPresets[size_t(state.aaPreset)].name;
    return fmt::format("MSAA {}x SSAA {}x{}", state.settings.msaa, state.settings.ssaa, state.settings.ssaa);
}

std::string stateSummary(const ViewerState& state)
{
    return fmt::format("{}, {}, {}{}{}", choiceName(setting("shading"), state.settings.shadingMode),
                       aaName(state), primitiveModeName(state.primitiveMode),
                       state.wireframe ? " + wireframe" : "",
                       state.model.isIdentity() ? "" : ", model " + modelSpecString(state.model));
}

std::string controlsHelp()
{
    std::string shadings, presets;
    // Five modes a line, continuing under the first, so the text fits 100 columns.
    for (size_t i = 0; i < kShadingKeyModes.size(); ++i)
        shadings += fmt::format("{}{} {}",
                                i == 0  ? ""
                                : i % 5 ? ", "
                                        : ",\n                     ",
                                i + 1, choiceName(setting("shading"), kShadingKeyModes[i]));
    for (size_t i = 0; i < kAaPresets.size(); ++i)
        presets += fmt::format("{}{}", i ? ", " : "", kAaPresets[i].name);
    return fmt::format(
        "  left drag          orbit around the target (elevation stops at +-{:g} degrees)\n"
        "  right/middle drag  pan: move the target in the view plane\n"
        "  wheel              zoom (distance x {:g} per step)\n"
        "  1-9                shading: {}\n"
        "  m                  anti-aliasing: {}\n"
        "  w                  wireframe overlay on/off\n"
        "  p                  primitive mode: triangles, lines, points\n"
        "  b                  switch backend (CUDA <-> Vulkan) where both exist\n"
        "  j l, i k, u o      move the model left/right, up/down (view plane), towards/away\n"
        "  x X, y Y, z Z      turn the model +-{:g} degrees about x, y, z (AX, AY, AZ of --model)\n"
        "  + -                scale the model up/down by a factor {:g} about its centre\n"
        "  r                  reset the camera (the auto camera) and the model (identity)\n"
        "  s                  save PNG + EXR + JSON of the current frame\n"
        "  Esc, q             quit\n",
        kMaxElevationDeg, kZoomFactorPerStep, shadings, presets, kModelStepDeg, kModelScaleStep);
}

}  // namespace sr
