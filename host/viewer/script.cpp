// script.cpp - parsing and replay of `raster view --script` files.
#include "viewer/script.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace sr {
namespace {

// A finite number filling the whole token (from_chars: no locale, no leading space or +).
bool parseNumber(const std::string& token, float& out)
{
    const char* end = token.data() + token.size();
    auto [ptr, ec] = std::from_chars(token.data(), end, out);
    return ec == std::errc() && ptr == end && std::isfinite(out);
}

bool parseSize(const std::string& token, uint32_t& out)
{
    const char* end = token.data() + token.size();
    auto [ptr, ec] = std::from_chars(token.data(), end, out);
    return ec == std::errc() && ptr == end && out >= 1 && out <= MAX_FRAMEBUFFER_DIM;
}

std::string trim(const std::string& text)
{
    const char* space = " \t\r\v\f";
    size_t first = text.find_first_not_of(space);
    if (first == std::string::npos) return "";
    return text.substr(first, text.find_last_not_of(space) - first + 1);
}

}  // namespace

Result<std::vector<ScriptEvent>> parseScript(const std::string& text, const std::string& name)
{
    std::vector<ScriptEvent> events;
    std::istringstream lines(text);
    std::string raw;
    for (int lineNumber = 1; std::getline(lines, raw); ++lineNumber) {
        const std::string line = trim(raw.substr(0, raw.find('#')));
        if (line.empty()) continue;
        std::istringstream in(line);
        std::vector<std::string> words;
        for (std::string word; in >> word;) words.push_back(word);
        auto bad = [&](const std::string& expected) {
            return makeError(ExitCode::Usage, "{}:{}: invalid '{}': expected {}", name, lineNumber, line,
                             expected);
        };
        ScriptEvent e;
        e.line = lineNumber;
        const std::string& command = words[0];
        if (command == "drag") {
            e.kind = ScriptEvent::Kind::Drag;
            const char* usage = "drag left|right|middle DX DY (pixels)";
            if (words.size() != 4) return bad(usage);
            if (words[1] == "left")
                e.button = MouseButton::Left;
            else if (words[1] == "right")
                e.button = MouseButton::Right;
            else if (words[1] == "middle")
                e.button = MouseButton::Middle;
            else
                return bad(usage);
            if (!parseNumber(words[2], e.dx) || !parseNumber(words[3], e.dy)) return bad(usage);
        } else if (command == "scroll") {
            e.kind = ScriptEvent::Kind::Scroll;
            if (words.size() != 2 || !parseNumber(words[1], e.steps)) return bad("scroll N (wheel steps)");
        } else if (command == "key") {
            e.kind = ScriptEvent::Kind::Key;
            const char* usage =
                "key K (one of 1-9, m, w, p, b, j, l, i, k, u, o, x, X, y, Y, z, Z, +, =, -, r, "
                "s, q, esc)";
            if (words.size() != 2) return bad(usage);
            e.key = words[1] == "esc" ? kKeyEscape : words[1].size() == 1 ? words[1][0] : char(0);
            if (!isBoundKey(e.key)) return bad(usage);
        } else if (command == "resize") {
            e.kind = ScriptEvent::Kind::Resize;
            if (words.size() != 3 || !parseSize(words[1], e.width) || !parseSize(words[2], e.height))
                return bad(fmt::format("resize W H (1..{} pixels each)", MAX_FRAMEBUFFER_DIM));
        } else if (command == "save") {
            e.kind = ScriptEvent::Kind::Save;
            // The prefix is the rest of the line, so paths with spaces work.
            if (words.size() < 2) return bad("save PATH_PREFIX");
            e.path = trim(line.substr(command.size()));
        } else if (command == "frame") {
            e.kind = ScriptEvent::Kind::Frame;
            if (words.size() != 1) return bad("frame (no arguments)");
        } else {
            return bad("drag, scroll, key, resize, save or frame");
        }
        events.push_back(std::move(e));
    }
    return events;
}

Result<std::vector<ScriptEvent>> loadScript(const std::string& path)
{
    std::ifstream file(path, std::ios::binary);
    if (!file) return makeError(ExitCode::Usage, "cannot read script '{}'", path);
    std::ostringstream text;
    text << file.rdbuf();
    if (file.bad()) return makeError(ExitCode::Usage, "cannot read script '{}'", path);
    return parseScript(text.str(), path);
}

ScriptEffect applyScriptEvent(ViewerState& state, const ScriptEvent& event)
{
    ScriptEffect effect;
    switch (event.kind) {
    case ScriptEvent::Kind::Drag: onDrag(state, event.button, event.dx, event.dy); break;
    case ScriptEvent::Kind::Scroll: onScroll(state, event.steps); break;
    case ScriptEvent::Kind::Key: onKey(state, event.key); break;
    case ScriptEvent::Kind::Resize: effect.resizeWindow = onResize(state, event.width, event.height); break;
    case ScriptEvent::Kind::Save: requestSave(state, event.path); break;
    case ScriptEvent::Kind::Frame: effect.renderFrame = true; break;
    }
    return effect;
}

}  // namespace sr
