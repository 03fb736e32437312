// file_write.cpp - see file_write.h.
#include "io/file_write.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

namespace sr {

namespace fs = std::filesystem;

namespace {

// This machine's name as temporaryPath writes it.
const std::string& hostTag()
{
    static const std::string tag = [] {
        char name[256] = {};
        if (gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return std::string("host");
        std::string t;
        for (const char* c = name; *c && t.size() < 32; ++c)
            t += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '-';
        return t;
    }();
    return tag;
}

bool allDigits(const std::string& text)
{
    return !text.empty() && text.size() <= 10 && text.find_first_not_of("0123456789") == std::string::npos;
}

// Whether process `pid` of this host has ended: it does not exist, or it is a zombie no one has reaped
// yet (a killed batch whose parent is gone, in a container whose first process reaps nothing). The
// calling process's own id counts as ended: a file found under it was left by an earlier process of
// that id, as this one has not written it yet when it looks.
bool processGone(const std::string& pidText)
{
    const long pid = std::stol(pidText);
    if (pid <= 0 || pid == long(getpid())) return true;
    if (kill(pid_t(pid), 0) != 0) return errno == ESRCH;
    // /proc/PID/stat: "PID (COMMAND) STATE ...", where COMMAND may hold spaces and parentheses.
    std::FILE* stat = std::fopen(fmt::format("/proc/{}/stat", pid).c_str(), "r");
    if (!stat) return false;
    char line[512] = {};
    const size_t n = std::fread(line, 1, sizeof line - 1, stat);
    std::fclose(stat);
    const char* paren = std::strrchr(line, ')');
    return n > 0 && paren && paren[1] == ' ' && (paren[2] == 'Z' || paren[2] == 'X');
}

}  // namespace

std::string temporaryPath(const std::string& path)
{
    return fmt::format("{}.tmp.{}.{}", path, hostTag(), getpid());
}

std::optional<TemporaryName> temporaryName(const std::string& fileName)
{
    const size_t tmp = fileName.rfind(".tmp.");
    if (tmp == std::string::npos || tmp == 0) return std::nullopt;
    const std::string tail = fileName.substr(tmp + 5);
    TemporaryName t;
    t.finalName = fileName.substr(0, tmp);
    if (allDigits(tail)) {  // PATH.tmp.<pid>, as older versions wrote
        t.writerGone = processGone(tail);
        return t;
    }
    const size_t dot = tail.rfind('.');
    if (dot == std::string::npos || dot == 0 || !allDigits(tail.substr(dot + 1))) return std::nullopt;
    t.writerGone = tail.substr(0, dot) == hostTag() && processGone(tail.substr(dot + 1));
    return t;
}

Status checkOutputTarget(const std::string& path)
{
    struct stat st {};
    if (lstat(path.c_str(), &st) != 0) {
        if (errno == ENOENT) return okStatus();
        return makeError(ExitCode::Usage, "cannot write '{}': {}", path, std::strerror(errno));
    }
    if (S_ISREG(st.st_mode)) return okStatus();
    const char* what = S_ISDIR(st.st_mode)    ? "a folder"
                       : S_ISLNK(st.st_mode)  ? "a symbolic link"
                       : S_ISCHR(st.st_mode)  ? "a character device"
                       : S_ISBLK(st.st_mode)  ? "a block device"
                       : S_ISFIFO(st.st_mode) ? "a FIFO"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    return makeError(ExitCode::Usage, "cannot write '{}': it exists and is {}, not a regular file", path,
                     what);
}

Status renameFile(const std::string& from, const std::string& to)
{
    auto target = checkOutputTarget(to);
    if (!target) {
        std::remove(from.c_str());
        return target.error();
    }
    if (std::rename(from.c_str(), to.c_str()) != 0) {
        const int saved = errno;
        std::remove(from.c_str());
        return makeError(ExitCode::Usage, "cannot rename '{}' to '{}': {}", from, to, std::strerror(saved));
    }
    return okStatus();
}

namespace {

// Writes `path`, naming `shown` in the error (the final name when `path` is its temporary one).
Status writeWhole(const std::string& path, const std::string& shown, const void* data, size_t bytes)
{
    const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return makeError(ExitCode::Usage, "cannot write '{}': {}", shown, std::strerror(errno));
    const auto* p = static_cast<const unsigned char*>(data);
    size_t left = bytes;
    int error = 0;
    while (left > 0) {
        const ssize_t n = write(fd, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            error = n < 0 ? errno : EIO;
            break;
        }
        p += n;
        left -= size_t(n);
    }
    // close() reports what a delayed write found (NFS, quotas): it is an error like any other.
    if (close(fd) != 0 && error == 0) error = errno;
    if (error != 0) {
        std::remove(path.c_str());
        return makeError(ExitCode::Usage, "cannot write '{}': {}", shown, std::strerror(error));
    }
    return okStatus();
}

}  // namespace

Status writeFile(const std::string& path, const void* data, size_t bytes)
{
    return writeWhole(path, path, data, bytes);
}

Status writeFileAtomically(const std::string& path, const void* data, size_t bytes)
{
    SR_TRY(checkOutputTarget(path));
    const std::string tmp = temporaryPath(path);
    SR_TRY(writeWhole(tmp, path, data, bytes));
    return renameFile(tmp, path);
}

FileGroup::~FileGroup()
{
    discard();
}

void FileGroup::discard()
{
    for (const Staged& f : staged_) std::remove(f.temporary.c_str());
    staged_.clear();
}

Status FileGroup::stage(const std::string& path, const void* data, size_t bytes)
{
    auto staged = [&]() -> Status {
        SR_TRY(checkOutputTarget(path));
        const std::string tmp = temporaryPath(path);
        SR_TRY(writeWhole(tmp, path, data, bytes));
        staged_.push_back({tmp, path});
        return okStatus();
    }();
    if (!staged) discard();
    return staged;
}

Status FileGroup::commit()
{
    for (const Staged& f : staged_) {
        auto target = checkOutputTarget(f.path);
        if (!target) {
            discard();
            return target.error();
        }
    }
    for (size_t i = 0; i < staged_.size(); ++i) {
        if (std::rename(staged_[i].temporary.c_str(), staged_[i].path.c_str()) == 0) continue;
        const int saved = errno;
        const Error error = makeError(ExitCode::Usage, "cannot rename '{}' to '{}': {}", staged_[i].temporary,
                                      staged_[i].path, std::strerror(saved));
        for (size_t j = 0; j < i; ++j) std::remove(staged_[j].path.c_str());
        discard();
        return error;
    }
    staged_.clear();
    return okStatus();
}

Status createParentFolder(const std::string& path)
{
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty()) return okStatus();
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) return makeError(ExitCode::Usage, "cannot create folder '{}': {}", parent.string(), ec.message());
    return okStatus();
}

std::string resolvedPath(const std::string& path)
{
    // realpath() for paths whose end does not exist yet: the components are taken one at a time, each
    // symbolic link replaced by its target, also one whose target does not exist (a link to a folder a
    // batch will create), and ".." applied to the resolved folder, as the kernel resolves it.
    std::error_code ec;
    const fs::path start = fs::absolute(path, ec);
    if (ec) return fs::path(path).lexically_normal().string();
    const fs::path relative = start.relative_path();
    std::deque<fs::path> left(relative.begin(), relative.end());
    fs::path resolved = start.root_path();
    int links = 0;
    while (!left.empty()) {
        const fs::path part = left.front();
        left.pop_front();
        if (part.empty() || part == ".") continue;
        if (part == "..") {
            resolved = resolved.parent_path();
            continue;
        }
        const fs::path next = resolved / part;
        struct stat st {};
        // Up to 40 links, as the kernel allows (ELOOP): a cycle ends there, with the rest as written.
        if (lstat(next.c_str(), &st) == 0 && S_ISLNK(st.st_mode) && ++links <= 40) {
            const fs::path target = fs::read_symlink(next, ec);
            if (!ec) {
                const fs::path targetParts = target.relative_path();
                const std::vector<fs::path> parts(targetParts.begin(), targetParts.end());
                left.insert(left.begin(), parts.begin(), parts.end());
                if (target.is_absolute()) resolved = target.root_path();
                continue;
            }
        }
        resolved = next;
    }
    return resolved.string();
}

bool hasExtension(const std::string& path, const std::string& extension)
{
    if (path.size() < extension.size()) return false;
    return std::equal(extension.begin(), extension.end(), path.end() - std::ptrdiff_t(extension.size()),
                      [](char a, char b) {
                          return std::tolower(static_cast<unsigned char>(a)) ==
                                 std::tolower(static_cast<unsigned char>(b));
                      });
}

Status checkOutputNames(const std::vector<OutputName>& outputs)
{
    for (size_t i = 0; i < outputs.size(); ++i) {
        const OutputName& a = outputs[i];
        if (a.path.empty()) continue;
        if (!a.extension.empty() && !hasExtension(a.path, a.extension))
            return makeError(ExitCode::Usage, "{} '{}' must end in {}", a.label, a.path, a.extension);
        for (size_t j = 0; j < i; ++j) {
            const OutputName& b = outputs[j];
            if (!b.path.empty() && resolvedPath(a.path) == resolvedPath(b.path))
                return makeError(ExitCode::Usage, "{} '{}' and {} '{}' name the same file", b.label, b.path,
                                 a.label, a.path);
        }
    }
    return okStatus();
}

}  // namespace sr
