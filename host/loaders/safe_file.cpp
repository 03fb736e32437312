// safe_file.cpp - readRegularFile: POSIX open/fstat/read, so that the file's type and size are known
// before the first byte is read.
#include "loaders/safe_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace sr {
namespace {

// What a non-regular file is, for the message; nullptr for a regular file.
const char* nonRegularKind(const struct stat& st)
{
    if (S_ISREG(st.st_mode)) return nullptr;
    if (S_ISDIR(st.st_mode)) return "a directory";
    if (S_ISFIFO(st.st_mode)) return "a FIFO (named pipe)";
    if (S_ISCHR(st.st_mode)) return "a character device";
    if (S_ISBLK(st.st_mode)) return "a block device";
    if (S_ISSOCK(st.st_mode)) return "a socket";
    return "not a regular file";
}

class Descriptor {
public:
    explicit Descriptor(int fd) : fd_(fd) {}
    ~Descriptor()
    {
        if (fd_ >= 0) ::close(fd_);
    }
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    int get() const { return fd_; }

private:
    int fd_;
};

}  // namespace

Result<std::vector<unsigned char>> readRegularFile(const std::string& path, uint64_t maxBytes,
                                                   const std::string& action)
{
    auto fail = [&](const std::string& why) {
        return makeError(ExitCode::Usage, "cannot {} '{}': {}", action, path, why);
    };
    auto refuse = [&](const struct stat& st) -> Error {
        if (const char* kind = nonRegularKind(st))
            return fail(fmt::format("it is {}, not a regular file", kind));
        return fail(
            fmt::format("it is {} bytes, over the limit of {} bytes", uint64_t(st.st_size), maxBytes));
    };
    auto acceptable = [&](const struct stat& st) {
        return S_ISREG(st.st_mode) && st.st_size >= 0 && uint64_t(st.st_size) <= maxBytes;
    };

    // Checked on the path first so that a device is never opened at all (opening one can have effects
    // of its own, a serial line's or a tape's), then again on the opened descriptor, which is what is
    // read: the path may have been replaced in between.
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return fail(std::strerror(errno));
    if (!acceptable(st)) return refuse(st);
    // O_NONBLOCK: should the path have become a FIFO since, open() returns at once instead of waiting
    // for a writer (a regular file ignores the flag).
    Descriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
    if (fd.get() < 0) return fail(std::strerror(errno));
    if (::fstat(fd.get(), &st) != 0) return fail(std::strerror(errno));
    if (!acceptable(st)) return refuse(st);

    std::vector<unsigned char> bytes(size_t(st.st_size));
    size_t used = 0;
    unsigned char probe[65536];
    for (;;) {
        // Past the size fstat reported, read into `probe`: most often that read only confirms the end of
        // the file, and the buffer is not grown for it. (A file may grow while it is read, and some,
        // such as those in /proc, report size 0.)
        bool past = used == bytes.size();
        unsigned char* into = past ? probe : bytes.data() + used;
        size_t room = past ? sizeof probe : bytes.size() - used;
        ssize_t got = ::read(fd.get(), into, room);
        if (got < 0) {
            if (errno == EINTR) continue;
            return fail(std::strerror(errno));
        }
        if (got == 0) break;
        if (past) {
            if (uint64_t(used) + uint64_t(got) > maxBytes)
                return fail(fmt::format("it grew past the limit of {} bytes while it was read", maxBytes));
            bytes.insert(bytes.end(), probe, probe + got);
        }
        used += size_t(got);
    }
    bytes.resize(used);
    return bytes;
}

}  // namespace sr
