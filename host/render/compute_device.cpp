// compute_device.cpp - stage names.
#include "render/compute_device.h"

namespace sr {

const char* stageName(uint32_t stage)
{
    return stage < STAGE_COUNT ? kStages[stage].name : "unknown";
}

}  // namespace sr
