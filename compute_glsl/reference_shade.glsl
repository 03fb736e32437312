// reference_shade.glsl - the shading of the `vulkan-graphics` reference backend's fragment stages
// (host/vulkan/vulkan_graphics.cpp), included after raster_shared.h and buffers.glsl by reference.frag
// (one sample per pixel, packed sRGB word) and reference_aa.frag (anti-aliased: linear colour); not a
// shader of its own. The two differ only in their outputs, whose types are fixed per shader.
// gl_PrimitiveID of the single indexed draw is the triangle id of the compute backends. Facing culling
// happens here, per triangle flag, because one draw has one pipeline cull mode and glTF doubleSided
// triangles must never be culled. The surface is derived as compute_glsl/shade.comp derives it
// (surfaceAt at the pixel centre, the same shadeSurface), with one deliberate difference: the base
// colour texture is sampled by the hardware, through a real image and sampler with the hardware's
// implicit derivatives, so that the compute path's software sampling is checked against it.
#ifndef RASTER_REFERENCE_SHADE_GLSL
#define RASTER_REFERENCE_SHADE_GLSL

// One combined image sampler per scene texture (at least one: a placeholder when the scene has none).
layout(constant_id = 2) const uint kTextureSlots = 1u;
layout(set = 1, binding = 0) uniform sampler2D baseTextures[kTextureSlots];

layout(location = 0) smooth in vec4 vTexcoords;
// Screen-linear texture coordinates as tc * w and w, both perspective-correct (reference.vert says why).
layout(location = 1) smooth in vec4 vTexcoordsTimesW;
layout(location = 2) smooth in float vClipW;

// The linear colour of triangle `id` at this fragment's pixel centre; discards the fragment where the
// triangle is culled or cut out by its alpha mask. Called once from main, in uniform control flow.
vec3 referenceShade(uint id)
{
    bool doubleSided = (triFlags[id] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    bool culled = (params.cullMode == CULL_BACK && !gl_FrontFacing) ||
                  (params.cullMode == CULL_FRONT && gl_FrontFacing);
    if (culled && !doubleSided) discard;
    uint i0 = indices[3u * id];
    uint i1 = indices[3u * id + 1u];
    uint i2 = indices[3u * id + 2u];
    SurfacePoint s = surfaceAt(params, int(gl_FragCoord.x), int(gl_FragCoord.y), positions[i0],
                               positions[i1], positions[i2], normals[i0], normals[i1], normals[i2]);
    // Ambient occlusion: what the host computed from this pipeline's own G-buffer (prepareAo).
    if (params.aoMode != AO_OFF)
        s.ao = aoShaded(
            ao[params.aoPlane * params.samplePlane + uint(gl_FragCoord.y) * params.width + uint(gl_FragCoord.x)]);
    vec4 white = vec4(1.0f);
    bool hasColors = params.hasColors != 0u;
    vec4 base = surfaceColor(s, hasColors ? colors[i0] : white, hasColors ? colors[i1] : white,
                             hasColors ? colors[i2] : white);
    // Hardware derivatives of the interpolated texture coordinates, taken here in uniform control flow.
    // The lookup below passes them explicitly, transformed like the coordinates, rather than letting
    // texture() differentiate the transformed coordinates: those depend on the material loaded from a
    // storage buffer, and llvmpipe's helper invocations read storage buffers as zeros, which breaks
    // implicit derivatives in every quad that a triangle edge crosses. (Implicit derivatives are by
    // definition these dFdx/dFdy, so on other devices this changes nothing.)
    vec4 tc = mix(vTexcoords, vTexcoordsTimesW / vClipW, bvec4(params.uvInterpolation == UV_AFFINE));
    vec4 tcDx = dFdx(tc), tcDy = dFdy(tc);
    vec2 uv = vec2(0.0f);
    float lambda = -128.0f;  // materialBaseColor's value without a texture
    vec3 emissive = vec3(0.0f);
    if (params.materialCount > 0u) {
        GpuMaterial m = materials[min(triMaterials[id], params.materialCount - 1u)];
        base = base * m.baseColorFactor;
        if (m.baseColorTexture < params.textureCount) {
            uv = materialTransformUv(m, texcoordSet(tc, m.texCoord));
            vec2 dx = materialTransformDerivative(m, texcoordSet(tcDx, m.texCoord));
            vec2 dy = materialTransformDerivative(m, texcoordSet(tcDy, m.texCoord));
            // Triangles of one draw use different textures, and indexing a sampler array with a value
            // that varies within a draw needs a device feature (shaderSampledImageArrayNonUniformIndexing)
            // that not every device has (llvmpipe of LLVM 15 lacks it). The loop index is uniform, so
            // each lookup is legal everywhere.
            vec4 texel = vec4(1.0f);
            for (uint k = 0u; k < kTextureSlots; ++k) {
                if (k == m.baseColorTexture) {
                    texel = textureGrad(baseTextures[k], uv, dx, dy);
                    // textureQueryLod has no explicit-gradient form: the debug view's level of detail
                    // is texture.h's formula on the same hardware derivatives.
                    ivec2 size = textureSize(baseTextures[k], 0);
                    lambda = textureLambda(dx, dy, uint(size.x), uint(size.y));
                }
            }
            base = base * texel;
        }
        // As the compute pipeline's visibility stages: a masked triangle covers no pixel whose alpha is
        // below the cutoff, so the cut-out shows in the id and depth images too.
        if ((triFlags[id] & TRI_FLAG_ALPHA_MASK) != 0u && base.w < m.alphaCutoff) discard;
        // Emission, as materialEmissive: the factor times the emissive texture, sampled by the hardware
        // like the base colour (its own coordinate set, no texture transform).
        emissive = vec3(m.emissive.x, m.emissive.y, m.emissive.z);
        if (m.emissiveTexture < params.textureCount && emissive != vec3(0.0f)) {
            vec2 euv = texcoordSet(tc, m.emissiveTexCoord);
            vec2 dx = texcoordSet(tcDx, m.emissiveTexCoord);
            vec2 dy = texcoordSet(tcDy, m.emissiveTexCoord);
            vec4 texel = vec4(1.0f);
            for (uint k = 0u; k < kTextureSlots; ++k)
                if (k == m.emissiveTexture) texel = textureGrad(baseTextures[k], euv, dx, dy);
            emissive = emissive * vec3(texel.x, texel.y, texel.z);
        }
    }
    return shadeSurface(params, id, s, base, emissive, uv, lambda);
}

#endif  // RASTER_REFERENCE_SHADE_GLSL
