// warnings.h - the one way the host code reports a warning: a part of the input dropped or drawn
// otherwise than asked (a triangle with a bad index, a texture that cannot load, a tessellation that
// keeps some triangles flat).
//
// A warning is one line. The command line prints each as "warning: TEXT" on stderr the moment it
// happens; a caller that hands warnings on as values (the library: raster::Scene::warnings, and the
// Python module's `warnings`) collects those of a call with a WarningCapture on its thread, and nothing
// is printed.
#ifndef RASTER_WARNINGS_H
#define RASTER_WARNINGS_H

#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "base/result.h"

namespace sr {

// Reports `text` (one line, no "warning: " prefix): to the innermost WarningCapture of this thread, or
// printed on stderr when there is none.
void warnLine(std::string text);

// Text arguments are bounded as in makeError (base/result.h).
template <typename... Args>
void warn(fmt::format_string<Args...> f, Args&&... args)
{
    warnLine(fmt::format(fmt::runtime(fmt::string_view(f)), detail::bounded(std::forward<Args>(args))...));
}

// Collects the warnings of this thread while it lives (captures nest: the innermost one collects).
class WarningCapture {
public:
    WarningCapture();
    ~WarningCapture();
    WarningCapture(const WarningCapture&) = delete;
    WarningCapture& operator=(const WarningCapture&) = delete;

    // The warnings collected so far, in order; the capture starts over empty.
    std::vector<std::string> take() { return std::exchange(lines_, {}); }

private:
    friend void warnLine(std::string text);
    std::vector<std::string> lines_;
    WarningCapture* outer_ = nullptr;
};

}  // namespace sr

#endif  // RASTER_WARNINGS_H
