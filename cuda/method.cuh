// method.cuh - the raster method a build is compiled for (template argument kMethod, RASTER_*;
// common/shared/methods.h): names the stages call for setup, bounds, tile tests and coverage, mapped
// to the method's functions at compile time, so the fixed8 builds hold the code they always had.
// compute_glsl/method.glsl is the twin (there one module per method).
namespace sr {

template <uint kMethod>
__device__ inline bool methodSetupTriangle(vec4 c0, vec4 c1, vec4 c2, uint triId, bool doubleSided,
                                           uint cullMode, uint width, uint height, uint bounds, TriSetup& t)
{
    if constexpr (kMethod == RASTER_FIXED8)
        return setupTriangle(c0, c1, c2, triId, doubleSided, cullMode, width, height, bounds, t);
    else if constexpr (kMethod == RASTER_FIXED4)
        return setupTriangleFixed4(c0, c1, c2, triId, doubleSided, cullMode, width, height, bounds, t);
    else
        return setupTriangleFloat(c0, c1, c2, triId, doubleSided, cullMode, width, height, bounds, t);
}

template <uint kMethod>
__device__ inline bool methodLineTriangle(const LineQuad& q, uint k, uint id, uint width, uint height,
                                          uint bounds, TriSetup& t)
{
    if constexpr (kMethod >= RASTER_FLOAT)
        return setupLineTriangleFloat(q, k, id, width, height, bounds, t);
    else
        return setupLineTriangle(q, k, id, width, height, bounds, t);
}

template <uint kMethod>
__device__ inline ivec4 methodPixelBounds(const TriSetup& t, uint width, uint height, uint bounds)
{
    if constexpr (kMethod >= RASTER_FLOAT)
        return floatPixelBounds(t, width, height, bounds);
    else
        return setupPixelBounds(t, width, height, bounds);
}

template <uint kMethod>
__device__ inline bool methodTouchesTile(const TriSetup& t, ivec4 bounds, int tx, int ty, uint sampleBounds)
{
    if constexpr (kMethod >= RASTER_FLOAT)
        return true;  // the bbox is the float methods' whole test (methods.h)
    else
        return triangleTouchesTile(t, bounds, tx, ty, sampleBounds);
}

template <uint kMethod>
__device__ inline bool methodTouchesPixels(const TriSetup& t, int x0, int y0, int x1, int y1,
                                           uint sampleBounds)
{
    if constexpr (kMethod >= RASTER_FLOAT)
        return true;
    else
        return triangleTouchesPixels(t, x0, y0, x1, y1, sampleBounds);
}

template <uint kMethod>
__device__ inline bool methodSample(const TriSetup& t, ivec2 p, float& depth)
{
    if constexpr (kMethod == RASTER_FLOAT)
        return floatSample(t, p, depth);
    else if constexpr (kMethod == RASTER_SCANLINE)
        return scanlineSample(t, p, depth);
    else
        return rasterSample(t, p, depth);
}

template <uint kMethod>
__device__ inline bool methodPixel(const TriSetup& t, int px, int py, float& depth)
{
    if constexpr (kMethod == RASTER_FLOAT)
        return floatPixel(t, px, py, depth);
    else if constexpr (kMethod == RASTER_SCANLINE)
        return scanlinePixel(t, px, py, depth);
    else
        return rasterPixel(t, px, py, depth);
}

template <uint kMethod>
__device__ inline uint methodCoverage(const TriSetup& t, uint count, int px, int py)
{
    if constexpr (kMethod == RASTER_FLOAT)
        return floatCoverage(t, count, px, py);
    else if constexpr (kMethod == RASTER_SCANLINE)
        return scanlineCoverage(t, count, px, py);
    else
        return pixelCoverage(t, count, px, py);
}

}  // namespace sr
