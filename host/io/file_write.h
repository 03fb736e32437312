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
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

// PATH.tmp.<pid>: where `path` is written before the rename. The process id keeps two processes that
// were given the same output (two shards run by hand with overlapping jobs) from writing into one file.
std::string temporaryPath(const std::string& path);

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

// The folder holding `path`, created with its parents when missing.
Status createParentFolder(const std::string& path);

// The path as the file system resolves it: absolute, with `.`, `..` and the symbolic links of its
// existing part resolved, so that two spellings of one file compare equal.
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
