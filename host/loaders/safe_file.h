// safe_file.h - reading the files a scene names, whatever they turn out to be.
//
// A scene file chooses the paths of its buffers, images and material files, so any of them may name a
// directory, a FIFO nobody writes to, a device such as /dev/zero, or a sparse file of terabytes.
// The scene loaders read every file through readRegularFile, which refuses all of those with a one-line
// error before reading a byte, instead of aborting on a huge allocation, blocking forever or reading
// without end.
#ifndef RASTER_SAFE_FILE_H
#define RASTER_SAFE_FILE_H

#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

// Largest scene file (.gltf, .glb, .obj, .mtl) and largest file a glTF names (buffer or image):
// 4 GiB - 1 byte. tinygltf takes a document's length as a 32-bit unsigned int, and the GLB header
// stores the file's length in one; the files a document names get the same bound.
constexpr uint64_t kMaxSceneFileBytes = 0xffffffffu;

// Largest encoded image file decoded through stb_image (an OBJ map_Kd, and a glTF image once read):
// 2 GiB - 1 byte, the most stb_image takes (its lengths are ints). That is also about what the largest
// image the texel limits allow (2^28 texels) needs at 16 bits per channel, RGBA, uncompressed.
constexpr uint64_t kMaxImageFileBytes = 0x7fffffffu;

// The whole content of `path`, which must be a regular file (after following symbolic links) of at
// most maxBytes bytes. The file is opened without blocking (a FIFO without a writer cannot stall the
// open) and its type and size are checked on the opened descriptor before anything is read; a file
// that grows past maxBytes while it is read is refused too. Errors are one line,
// "cannot <action> '<path>': <why>", e.g. "cannot read image 'a/b': it is a directory, not a regular
// file": `action` is what the caller was doing ("load", "read image", ...).
Result<std::vector<unsigned char>> readRegularFile(const std::string& path, uint64_t maxBytes,
                                                   const std::string& action);

}  // namespace sr

#endif  // RASTER_SAFE_FILE_H
