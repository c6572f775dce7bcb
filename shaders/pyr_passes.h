/* Every pass's shared functions, for the code that compiles them: the GPU dialects (pyr_opencl.cl,
 * pyr_vulkan.comp, pyr_cuda.cuh), the CPU backend (backends/cpu/cpu_dialect.hpp) and the dialect checks
 * (tests/dialect/). The includer defines the accessor macros first (pyr_shim.h lists them). Adding a pass: its
 * header here. */
#ifndef PYR_PASSES_H
#define PYR_PASSES_H

#include "pyr_color.h"
#include "pyr_compact.h"
#include "pyr_depth.h"
#include "pyr_edges.h"
#include "pyr_fill.h"
#include "pyr_labels.h"
#include "pyr_merge.h"
#include "pyr_metric.h"
#include "pyr_mip.h"
#include "pyr_normals.h"
#include "pyr_quantize.h"
#include "pyr_robust.h"
#include "pyr_stats.h"
/* The compaction's workgroup scan: the GPU dialects' (the CPU backend numbers the labels in one sweep). */
#if !defined(PYR_CPP)
#include "pyr_scan.h"
#endif

#endif /* PYR_PASSES_H */
