// window.cpp - see window.h.
#include "viewer/window.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <cstdlib>
#include <string>

namespace sr {
namespace {

// GLFW reports errors through a callback; the last one explains a failed call.
std::string& lastGlfwError()
{
    static std::string error;
    return error;
}

void onGlfwError(int code, const char* description)
{
    lastGlfwError() = std::string(description) + " (GLFW error " + std::to_string(code) + ")";
}

Window* self(GLFWwindow* w)
{
    return static_cast<Window*>(glfwGetWindowUserPointer(w));
}

}  // namespace

Result<std::unique_ptr<Window>> Window::open(uint32_t width, uint32_t height, const std::string& title)
{
    glfwSetErrorCallback(onGlfwError);
    if (glfwInit() != GLFW_TRUE)
        return makeError(ExitCode::Usage,
                         "view: no display to open a window on ({}); use `raster render` to write images "
                         "without one",
                         lastGlfwError().empty() ? "GLFW could not initialise" : lastGlfwError());
    if (glfwVulkanSupported() != GLFW_TRUE) {
        glfwTerminate();
        return makeError(ExitCode::Usage,
                         "view: GLFW finds no Vulkan loader to present with; use `raster render`");
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    std::unique_ptr<Window> w(new Window());
    w->window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
    if (w->window_ == nullptr) {
        glfwTerminate();
        return makeError(ExitCode::Usage, "view: cannot create a {}x{} window ({}); use `raster render`",
                         width, height, lastGlfwError());
    }
    glfwSetWindowUserPointer(w->window_, w.get());
    glfwSetCursorPosCallback(w->window_, onCursor);
    glfwSetScrollCallback(w->window_, onScroll);
    glfwSetKeyCallback(w->window_, onKey);
    glfwSetCharCallback(w->window_, onChar);
    glfwSetFramebufferSizeCallback(w->window_, onResize);
    return w;
}

Window::~Window()
{
    if (window_ != nullptr) glfwDestroyWindow(window_);
    glfwTerminate();
}

PresentTarget Window::presentTarget() const
{
    PresentTarget target;
    uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    for (uint32_t i = 0; i < count; ++i) target.instanceExtensions.push_back(names[i]);
    GLFWwindow* window = window_;
    target.createSurface = [window](VkInstance instance, VkSurfaceKHR* surface) {
        return glfwCreateWindowSurface(instance, window, nullptr, surface);
    };
    return target;
}

std::vector<InputEvent> Window::poll()
{
    glfwPollEvents();
    std::vector<InputEvent> events;
    events.swap(pending_);
    return events;
}

bool Window::closeRequested() const
{
    return glfwWindowShouldClose(window_) == GLFW_TRUE;
}

void Window::setTitle(const std::string& title)
{
    glfwSetWindowTitle(window_, title.c_str());
}

Status Window::resize(uint32_t width, uint32_t height)
{
    glfwSetWindowSize(window_, int(width), int(height));
    for (int k = 0; k < 100; ++k) {
        uint32_t w = 0, h = 0;
        glfwPollEvents();
        framebufferSize(w, h);
        if (w == width && h == height) return okStatus();
        glfwWaitEventsTimeout(0.01);
    }
    return makeError(ExitCode::Runtime, "view: the window system did not resize the window to {}x{}", width,
                     height);
}

void Window::framebufferSize(uint32_t& width, uint32_t& height) const
{
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    width = uint32_t(w > 0 ? w : 0);
    height = uint32_t(h > 0 ? h : 0);
}

// A drag is the cursor's motion while a button is held, the first held button deciding which.
void Window::onCursor(GLFWwindow* w, double x, double y)
{
    Window* me = self(w);
    if (me->haveCursor_) {
        const int buttons[3] = {GLFW_MOUSE_BUTTON_LEFT, GLFW_MOUSE_BUTTON_RIGHT, GLFW_MOUSE_BUTTON_MIDDLE};
        const MouseButton names[3] = {MouseButton::Left, MouseButton::Right, MouseButton::Middle};
        for (int b = 0; b < 3; ++b)
            if (glfwGetMouseButton(w, buttons[b]) == GLFW_PRESS) {
                InputEvent e;
                e.kind = InputEvent::Kind::Drag;
                e.button = names[b];
                e.dx = x - me->lastX_;
                e.dy = y - me->lastY_;
                me->pending_.push_back(e);
                break;
            }
    }
    me->lastX_ = x;
    me->lastY_ = y;
    me->haveCursor_ = true;
}

void Window::onScroll(GLFWwindow* w, double, double dy)
{
    InputEvent e;
    e.kind = InputEvent::Kind::Scroll;
    e.dy = dy;
    self(w)->pending_.push_back(e);
}

// Escape has no character; every other control key arrives through onChar, layout-aware.
void Window::onKey(GLFWwindow* w, int key, int, int action, int)
{
    if (action != GLFW_PRESS || key != GLFW_KEY_ESCAPE) return;
    InputEvent e;
    e.kind = InputEvent::Kind::Key;
    e.key = int(kKeyEscape);
    self(w)->pending_.push_back(e);
}

void Window::onChar(GLFWwindow* w, unsigned codepoint)
{
    if (codepoint >= 128) return;
    InputEvent e;
    e.kind = InputEvent::Kind::Key;
    e.key = int(codepoint);
    self(w)->pending_.push_back(e);
}

void Window::onResize(GLFWwindow* w, int width, int height)
{
    InputEvent e;
    e.kind = InputEvent::Kind::Resize;
    e.dx = width;
    e.dy = height;
    self(w)->pending_.push_back(e);
}

}  // namespace sr
