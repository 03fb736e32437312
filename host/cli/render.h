// render.h - `raster render`: one frame, or a turntable of frames, through the library's raster::Session.
#ifndef RASTER_CLI_RENDER_H
#define RASTER_CLI_RENDER_H

#include <string>

#include "base/result.h"
#include "settings/schema.h"

namespace sr {

struct RenderCommand {
    std::string scenePath;
    std::string backend = "auto";
    int device = -1;
    std::string output;  // -o; empty: render.png, unless --aov is given (then the EXR alone)
    std::string aovPath;
    std::string statsPath;
    uint32_t frames = 0;     // --frames N: a turntable of N frames (0: one render)
    std::string orbitRange;  // --orbit AZ0:AZ1: the turntable's azimuths
    bool quiet = false;
    std::string quality;    // --quality psnr:N: the settings come from the study's data (study/quality.h)
    std::string studyPath;  // --study FILE: ... from this study JSON instead of measuring
    std::string pngCompression, exrCompression;    // --png-compression, --exr-compression; empty: not given
    RenderOptions options = imageRenderOptions();  // every render setting (settings/schema.h)
};

Status runRender(RenderCommand& cmd);

}  // namespace sr

#endif  // RASTER_CLI_RENDER_H
