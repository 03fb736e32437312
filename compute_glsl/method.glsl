// method.glsl - the raster method a module is built for (RASTER_METHOD, a preprocessor definition,
// RASTER_FIXED8 unless CMakeLists.txt sets it; common/shared/methods.h): names the stages call for
// setup, bounds, tile tests and coverage, mapped to the method's functions. setup, bin_count, bin_fill
// and raster_tiles are compiled once per method, so the fixed8 modules hold the code they always had
// (NVIDIA's compiler is sensitive to extra code in a module; setup.comp). cuda/method.cuh is the twin.
#ifndef RASTER_METHOD_GLSL
#define RASTER_METHOD_GLSL

#ifndef RASTER_METHOD
#define RASTER_METHOD RASTER_FIXED8
#endif

#if RASTER_METHOD == RASTER_FIXED8 || RASTER_METHOD == RASTER_FIXED4
#if RASTER_METHOD == RASTER_FIXED8
#define methodSetupTriangle setupTriangle
#else
#define methodSetupTriangle setupTriangleFixed4
#endif
#define methodLineTriangle setupLineTriangle
#define methodPixelBounds setupPixelBounds
#define methodTouchesTile triangleTouchesTile
#define methodTouchesPixels triangleTouchesPixels
#define methodSample rasterSample
#define methodPixel rasterPixel
#define methodCoverage pixelCoverage
#define METHOD_INTEGER_EDGES 1  // exact integer edge functions: the small-triangle loop may use SmallEdges
#else
#define METHOD_INTEGER_EDGES 0
#define methodSetupTriangle setupTriangleFloat
#define methodLineTriangle setupLineTriangleFloat
#define methodPixelBounds floatPixelBounds
#define methodTouchesTile(t, bounds, tx, ty, sampleBounds) true
#define methodTouchesPixels(t, x0, y0, x1, y1, sampleBounds) true
#if RASTER_METHOD == RASTER_FLOAT
#define methodSample floatSample
#define methodPixel floatPixel
#define methodCoverage floatCoverage
#else
#define methodSample scanlineSample
#define methodPixel scanlinePixel
#define methodCoverage scanlineCoverage
#endif
#endif

#endif  // RASTER_METHOD_GLSL
