#pragma once
// pyrseg: fast bridgeless pyramid segmentation of organized point clouds.
#include "pyrseg/backend.hpp"
#include "pyrseg/cloud.hpp"
#include "pyrseg/depth.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/scene.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/version.hpp"
// The file formats (pyrseg::io; link pyrseg::io, or pkg-config pyrseg-io), where this install has them.
#if __has_include("pyrseg/io_export.hpp")
#include "pyrseg/io.hpp"
#endif
