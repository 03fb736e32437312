// cuda_check.h - every CUDA runtime call goes through CUDA_TRY, which turns a failure into an
// sr::Error naming the call, the CUDA error and the source line.
#ifndef RASTER_CUDA_CHECK_H
#define RASTER_CUDA_CHECK_H

#include <cuda_runtime.h>

#include "base/result.h"

#define CUDA_TRY(expr)                                                                            \
    do {                                                                                          \
        cudaError_t cuda_try_err_ = (expr);                                                       \
        if (cuda_try_err_ != cudaSuccess)                                                         \
            return ::sr::makeError(::sr::ExitCode::Runtime, "cuda: {} failed: {} ({}:{})", #expr, \
                                   cudaGetErrorString(cuda_try_err_), __FILE__, __LINE__);        \
    } while (0)

#endif  // RASTER_CUDA_CHECK_H
