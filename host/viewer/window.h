// window.h - the viewer's window (GLFW): creation with a clear error where there is no display, the
// Vulkan surface it offers to a presentation context, and its input turned into a queue of events that
// the viewer applies exactly as it applies a replayed script (host/viewer/script.h).
#ifndef RASTER_VIEWER_WINDOW_H
#define RASTER_VIEWER_WINDOW_H

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "base/result.h"
#include "viewer/controls.h"
#include "vulkan/vulkan_context.h"

struct GLFWwindow;

namespace sr {

// One input event in window pixels. Drag: the cursor moved by (dx, dy) with `button` held. Scroll: dy wheel
// steps (positive away from the user). Key: `key` is the character ('1', 'm', ...) or kKeyEscape
// (viewer/controls.h). Resize: the framebuffer is now dx x dy pixels.
struct InputEvent {
    enum class Kind { Drag, Scroll, Key, Resize };
    Kind kind = Kind::Key;
    MouseButton button = MouseButton::Left;
    double dx = 0.0, dy = 0.0;
    int key = 0;
};

class Window {
public:
    // Opens a window of width x height pixels. Without a display (no X server, no DISPLAY) a one-line
    // Usage error that points to `raster render`.
    static Result<std::unique_ptr<Window>> open(uint32_t width, uint32_t height, const std::string& title);
    ~Window();
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    // What a VulkanContext needs to present here.
    PresentTarget presentTarget() const;
    // Processes the window system's events and returns the input they carried, in order.
    std::vector<InputEvent> poll();
    bool closeRequested() const;
    void setTitle(const std::string& title);
    // Asks for a width x height framebuffer and waits (up to a second) until the window system gives
    // it, so that a scripted resize is in place before the next frame.
    Status resize(uint32_t width, uint32_t height);
    // The framebuffer's size in pixels (0 x 0 while minimized).
    void framebufferSize(uint32_t& width, uint32_t& height) const;

private:
    Window() = default;
    static void onCursor(GLFWwindow* w, double x, double y);
    static void onScroll(GLFWwindow* w, double dx, double dy);
    static void onKey(GLFWwindow* w, int key, int scancode, int action, int mods);
    static void onChar(GLFWwindow* w, unsigned codepoint);
    static void onResize(GLFWwindow* w, int width, int height);

    GLFWwindow* window_ = nullptr;
    std::vector<InputEvent> pending_;
    double lastX_ = 0.0, lastY_ = 0.0;
    bool haveCursor_ = false;
};

}  // namespace sr

#endif  // RASTER_VIEWER_WINDOW_H
