// warnings.cpp - see warnings.h.
#include "base/warnings.h"

#include <cstdio>

#include "base/result.h"

namespace sr {
namespace {

thread_local WarningCapture* innermost = nullptr;

}  // namespace

WarningCapture::WarningCapture() : outer_(innermost)
{
    innermost = this;
}

WarningCapture::~WarningCapture()
{
    innermost = outer_;
}

void warnLine(std::string text)
{
    // One line, bounded as the command line bounds its messages, whatever the input quoted in it.
    text = clippedText(text, 2 * kMaxQuotedBytes);
    if (innermost) {
        innermost->lines_.push_back(std::move(text));
        return;
    }
    fmt::print(stderr, "warning: {}\n", text);
}

}  // namespace sr
