// file_write.h - every output file the project writes goes through here: written whole under a
// temporary name beside it, checked through close(), and renamed into place, so that a full disk, a
// full device or a killed process never leaves a partial or empty file under the final name, and a
// failure is always an error. A final name that exists and is not a regular file (a device node such
// as /dev/full, a folder, a FIFO, a symbolic link) is refused, never replaced.
//
// The renames protect against failed writes and killed processes, not against power cuts (nothing is
// fsynced).
#ifndef RASTER_IO_FILE_WRITE_H
#define RASTER_IO_FILE_WRITE_H

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

// PATH.tmp.<host>.<pid>: where `path` is written before the rename. The host name (letters, digits and
// '-' of it, at most 32) and the process id keep two processes that were given the same output (two
// batches of one manifest, on one machine or on two sharing the folder) from writing into one file,
// and tell a leftover of a killed process from the file of one still writing (temporaryName).
std::string temporaryPath(const std::string& path);

// What a file name made by temporaryPath says: the final file's name, and whether its writer is gone (a
// process of this host that no longer runs, or a name of the older PATH.tmp.<pid> form whose process
// does not run here). A temporary of another host is never known to be gone. nullopt for other names.
struct TemporaryName {
    std::string finalName;
    bool writerGone = false;
};
std::optional<TemporaryName> temporaryName(const std::string& fileName);

// An error unless `path` is absent or a regular file (checked without following a final symbolic link).
Status checkOutputTarget(const std::string& path);

// Renames `from` onto `to` after checkOutputTarget(to) (atomic within a file system); on a failure
// `from` is removed.
Status renameFile(const std::string& from, const std::string& to);

// `bytes` written to `path` (a temporary name; no rename): every write() and the close() checked; on a
// failure the file is removed.
Status writeFile(const std::string& path, const void* data, size_t bytes);

// checkOutputTarget(path), then `bytes` written to temporaryPath(path) and renamed onto `path`.
Status writeFileAtomically(const std::string& path, const void* data, size_t bytes);

// The files of one job or command, whole or absent together: stage() writes each under its temporary
// name (checkOutputTarget first), commit() renames them all into place in the order they were staged.
// A failure leaves none of them: a group that is not committed (a later file failed to encode or
// write: a full disk) removes its temporaries; commit() checks every target before the first rename,
// and if a rename still fails it removes the files it already renamed and the remaining temporaries.
// A batch stages a job's sidecar last, so that it is renamed only after every output it vouches for.
class FileGroup {
public:
    FileGroup() = default;
    FileGroup(const FileGroup&) = delete;
    FileGroup& operator=(const FileGroup&) = delete;
    ~FileGroup();

    Status stage(const std::string& path, const void* data, size_t bytes);
    Status commit();

private:
    void discard();
    struct Staged {
        std::string temporary, path;
    };
    std::vector<Staged> staged_;
};

// The folder holding `path`, created with its parents when missing.
Status createParentFolder(const std::string& path);

// The path as the file system resolves it: absolute, with `.`, `..` and every symbolic link along it
// resolved, dangling ones too (a link to a folder that does not exist yet), so that two spellings of one
// file compare equal before either exists.
std::string resolvedPath(const std::string& path);

// Whether `path` ends in `extension` (".png"), ignoring case.
bool hasExtension(const std::string& path, const std::string& extension);

// One output of a command: how the user named it (its option or key), its path (or pattern), and the
// extension its format needs ("" for any).
struct OutputName {
    std::string label;      // "-o", "--aov", "output", ...
    std::string path;       // empty: not written
    std::string extension;  // ".png", ".exr", or "" for any
};

// Every named output has its format's extension, and no two name the same file however they are spelled
// (resolvedPath): otherwise a one-line error naming both.
Status checkOutputNames(const std::vector<OutputName>& outputs);

}  // namespace sr

#endif  // RASTER_IO_FILE_WRITE_H
