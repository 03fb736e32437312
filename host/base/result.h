// result.h - errors as values for the host code.
//
// Library-style host functions return Result<T>: either a value or an Error holding a one-line
// message and the process exit code it maps to. Only main() turns an Error into output and an exit
// code (host/cli/main.cpp), so every failure path reports exactly one line.
#ifndef RASTER_RESULT_H
#define RASTER_RESULT_H

#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

#include <fmt/format.h>

namespace sr {

// Exit codes of the `raster` tool.
enum class ExitCode : int {
    Ok = 0,
    CompareFailed = 1,  // `raster compare` found a difference beyond tolerance
    JobsFailed = 1,     // `raster batch` rendered the rest, but some jobs failed (named in its summary)
    Usage = 2,          // bad arguments, missing backend, unreadable or malformed input
    Runtime = 3,        // a GPU API call failed at run time
};

struct Error {
    std::string message;  // one line, no trailing newline
    ExitCode code = ExitCode::Usage;
};

// `text` as part of a one-line message: control and non-ASCII bytes (a library's message may quote bytes
// of the file it failed on, newlines included) become '?'.
inline std::string printableText(const char* text)
{
    std::string out = text ? text : "";
    for (char& c : out)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    return out;
}

// Quoted input (a key, a value, a path, a name the user gave) in a one-line message: control bytes become
// '?', and text longer than `limit` bytes is cut to its first `limit` (at a UTF-8 character boundary)
// followed by "... (N bytes)", so that a 10 MB key or file name still makes a readable line.
inline std::string clippedText(const std::string& text, size_t limit = 100)
{
    size_t keep = text.size();
    if (keep > limit) {
        keep = limit;
        while (keep > 0 && (static_cast<unsigned char>(text[keep]) & 0xC0) == 0x80) --keep;
    }
    std::string out = text.substr(0, keep);
    for (char& c : out)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
    if (keep < text.size()) out += fmt::format("... ({} bytes)", text.size());
    return out;
}
// clippedText in single quotes.
inline std::string quotedInput(const std::string& text, size_t limit = 100)
{
    return "'" + clippedText(text, limit) + "'";
}

// The longest piece of text a message takes whole: a safety net under the quoting of input
// (quotedInput, 100 bytes), which leaves room for a nested message quoting input of its own.
constexpr size_t kMaxQuotedBytes = 1000;

namespace detail {

// A message's argument: text bounded (clippedText, kMaxQuotedBytes), anything else as it is.
template <typename T>
decltype(auto) bounded(T&& arg)
{
    using D = std::decay_t<T>;
    if constexpr (std::is_same_v<D, std::string> || std::is_same_v<D, const char*> ||
                  std::is_same_v<D, char*> || std::is_same_v<D, std::string_view>)
        return clippedText(std::string(arg), kMaxQuotedBytes);
    else
        return std::forward<T>(arg);
}

}  // namespace detail

// An error whose message quotes every text argument bounded (detail::bounded): a 10 MB key, path or
// value the user gave still makes a readable line.
template <typename... Args>
Error makeError(ExitCode code, fmt::format_string<Args...> f, Args&&... args)
{
    return Error{fmt::format(fmt::runtime(fmt::string_view(f)), detail::bounded(std::forward<Args>(args))...),
                 code};
}

template <typename T>
class [[nodiscard]] Result {
public:
    Result(T value) : v_(std::move(value)) {}
    Result(Error error) : v_(std::move(error)) {}

    bool ok() const { return v_.index() == 0; }
    explicit operator bool() const { return ok(); }
    T& value() { return std::get<0>(v_); }
    const T& value() const { return std::get<0>(v_); }
    T& operator*() { return value(); }
    T* operator->() { return &value(); }
    const Error& error() const { return std::get<1>(v_); }

private:
    std::variant<T, Error> v_;
};

// Result of an operation with no value.
struct Unit {};
using Status = Result<Unit>;
inline Status okStatus()
{
    return Unit{};
}

}  // namespace sr

// Propagates an error from an expression returning Result/Status: `SR_TRY(device.upload(...));`
#define SR_TRY(expr)                                             \
    do {                                                         \
        auto sr_try_result_ = (expr);                            \
        if (!sr_try_result_.ok()) return sr_try_result_.error(); \
    } while (0)

#endif  // RASTER_RESULT_H
