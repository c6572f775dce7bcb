#version 450
/* GLSL: the entry points (shaders/pyr_entries.h) over the dialect of shaders/pyr_glsl.h. The build compiles this
 * file once per kernel of the table (shaders/pyr_kernels.h), with -DPYR_ENTRY_<NAME>, to SPIR-V (glslangValidator),
 * checks it with spirv-val and embeds it (cmake/CompileSpirv.cmake). */
#extension GL_GOOGLE_include_directive : require
#define PYR_GLSL 1
#include "pyr_glsl.h"

#include "pyr_entries.h"
