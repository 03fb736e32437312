// reference_visibility_aa.frag - fragment stage of the `vulkan-graphics` visibility pass with
// anti-aliasing: reference_visibility.frag with reference_aa.frag's float outputs. The colour is the
// linear background (specialization constants), the id is gl_PrimitiveID as an exact float; early
// fragment tests run the depth test per sample before the shader, and the pipeline culls.
#version 460

layout(early_fragment_tests) in;
layout(constant_id = 3) const float kBackgroundR = 0.0f;
layout(constant_id = 4) const float kBackgroundG = 0.0f;
layout(constant_id = 5) const float kBackgroundB = 0.0f;

layout(location = 0) out vec4 outColor;
layout(location = 1) out float outId;

void main()
{
    outColor = vec4(kBackgroundR, kBackgroundG, kBackgroundB, 1.0f);
    outId = float(gl_PrimitiveID);
}
