#version 450
// Every shared pass function as GLSL (glslangValidator -> SPIR-V, then spirv-val), over the Vulkan backend's own
// dialect and buffers (shaders/pyr_glsl.h), to keep shaders/ within the dialect. The entry points themselves
// (shaders/pyr_vulkan.comp) are compiled and checked by the build (cmake/CompileSpirv.cmake).
#extension GL_GOOGLE_include_directive : require
#define PYR_GLSL 1
#include "pyr_glsl.h"

#include "check_calls.h"

layout(std430, set = 0, binding = PYR_BUFFER_COUNT + 2) buffer PyrCheckOut { int pyr_check_out[]; };
layout(local_size_x = 8, local_size_y = 8) in;
void main() {
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    pyr_check_out[y * 64u + x] = pyr_check_all(PYR_ENTRY_CTX, x, y);
}
