// script.h - `raster view --script FILE`: a replayable sequence of input events, so the window can be
// driven without a person (tests under Xvfb, reproducible screenshots).
//
// One event per line; `#` starts a comment; blank lines are skipped:
//   drag left|right|middle DX DY   a drag by (DX, DY) window pixels, y down
//   scroll N                       N wheel steps (positive: towards the scene; fractions allowed)
//   key K                          K a bound key character (controls.h) or `esc`
//   resize W H                     the window's framebuffer becomes W x H pixels
//   save PREFIX                    PREFIX.png, PREFIX.exr and PREFIX.json of the current frame
//   frame                          draw and present one frame
#ifndef RASTER_SCRIPT_H
#define RASTER_SCRIPT_H

#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"
#include "viewer/controls.h"

namespace sr {

struct ScriptEvent {
    enum class Kind { Drag, Scroll, Key, Resize, Save, Frame };
    Kind kind = Kind::Frame;
    int line = 0;                            // 1-based line of the script it came from
    MouseButton button = MouseButton::Left;  // Drag
    float dx = 0.0f, dy = 0.0f;              // Drag: window pixels
    float steps = 0.0f;                      // Scroll
    char key = 0;                            // Key: as onKey takes it
    uint32_t width = 0, height = 0;          // Resize
    std::string path;                        // Save: the path prefix
};

// Parses a script's text; `name` (the file) goes into errors: "NAME:LINE: ..." on one line, for the first
// bad line.
Result<std::vector<ScriptEvent>> parseScript(const std::string& text, const std::string& name);
// Reads and parses the file at `path`.
Result<std::vector<ScriptEvent>> loadScript(const std::string& path);

// What the window does for an event beyond the requests the state carries (quit, save, scene, backend).
struct ScriptEffect {
    bool renderFrame = false;   // `frame`: draw and present a frame now
    bool resizeWindow = false;  // `resize`: make the window state.settings.width x height
};

// Applies one event to the state through the controls' functions (onDrag, onScroll, onKey, onResize,
// requestSave), exactly as the window's callbacks do for live input.
ScriptEffect applyScriptEvent(ViewerState& state, const ScriptEvent& event);

}  // namespace sr

#endif  // RASTER_SCRIPT_H
