// frame_files.h - the files of one rendered frame (the colour as PNG or NPY, the AOVs as EXR, the
// statistics as JSON), written the same way by `raster render`, its turntable, `raster batch`, the viewer's
// saves and the library's raster::writePng / writeExr. Not installed.
#ifndef RASTER_FRAME_FILES_H
#define RASTER_FRAME_FILES_H

#include <string>

#include "raster/raster.h"

#include "base/result.h"
#include "io/file_write.h"
#include "io/image_io.h"

namespace sr {

struct OutputPaths {
    std::string png;    // colour image: an sRGB PNG, or the same pixels as a NumPy array when it ends in .npy
    std::string aov;    // EXR of the AOVs; empty: none
    std::string stats;  // JSON statistics; empty: none
};

// Time a frame's files took, ms: encoding the colour image (PNG or NPY); computing and encoding the EXR's
// channels and the JSON; writing them under their temporary names.
struct OutputTimes {
    double encode = 0.0, aux = 0.0, write = 0.0;
};

// Whether the host stores a word's low byte first (a frame's RGBA bytes are then its pixel words).
bool littleEndianHost();

// A public frame's colour as the encoders take it (a word per pixel, R in the low byte), and its AOVs in
// the layout of the EXR (planes; every sample's id and depth spread per pixel; the linear colour decoded
// from the sRGB codes when withColor). The surface AOVs come from `surfacePlanes` when given (taken out of
// it: a render that kept them as planes, RenderControl::aovPlanes), else from the frame's arrays.
RgbaImage colorImage(const raster::Frame& frame);
AovImage aovImage(const raster::Frame& frame, bool withColor = false, AovImage* surfacePlanes = nullptr);
// Who drew the frame, as its PNG and EXR record it (ImageOrigin: the backend and the device's name).
ImageOrigin outputOrigin(const raster::Frame& frame);

// Encodes the frame's colour image (PNG or NPY, by its extension), its EXR (what aovImage holds) and its
// statistics (Frame::statsJson) where `paths` names them (an empty path: none), the images tagged with
// outputOrigin, and stages them in `files` (files.commit() puts them in place: every file or none). `times`,
// when given, receives what each part took; `surfacePlanes` as aovImage takes it.
Status stageFrame(FileGroup& files, const raster::Frame& frame, const OutputPaths& paths,
                  const ImageEncoding& encoding, OutputTimes* times = nullptr,
                  AovImage* surfacePlanes = nullptr);

}  // namespace sr

#endif  // RASTER_FRAME_FILES_H
