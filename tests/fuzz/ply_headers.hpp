#pragma once
// The valid PLY headers that fuzz_ply_body puts before the fuzzed body: most whole-file inputs stop at the strict
// header check (io/ply.cpp), so only bodies reach PCL's data parsing through this harness. The seed generator writes
// a body for each. The first input byte chooses the header.
#include <array>
#include <string_view>

namespace pyrseg::fuzz {

struct PlyHeader {
    std::string_view name;
    std::string_view text;
};

// A 4 x 3 grid; with range_grid, 10 vertices for 12 cells.
inline constexpr std::array<PlyHeader, 6> kPlyHeaders = {{
    {"ascii",
     "ply\nformat ascii 1.0\nobj_info num_cols 4\nobj_info num_rows 3\nelement vertex 12\n"
     "property float x\nproperty float y\nproperty float z\nend_header\n"},
    {"binary_le",
     "ply\nformat binary_little_endian 1.0\nobj_info num_cols 4\nobj_info num_rows 3\n"
     "element vertex 12\nproperty float x\nproperty float y\nproperty float z\nend_header\n"},
    {"ascii_range_grid",
     "ply\nformat ascii 1.0\nobj_info num_cols 4\nobj_info num_rows 3\nelement vertex 10\n"
     "property float x\nproperty float y\nproperty float z\nelement range_grid 12\n"
     "property list uchar int vertex_indices\nend_header\n"},
    {"binary_le_range_grid",
     "ply\nformat binary_little_endian 1.0\nobj_info num_cols 4\nobj_info num_rows 3\n"
     "element vertex 10\nproperty float x\nproperty float y\nproperty float z\n"
     "element range_grid 12\nproperty list uchar int vertex_indices\nend_header\n"},
    {"binary_be_normals",
     "ply\nformat binary_big_endian 1.0\nobj_info num_cols 4\nobj_info num_rows 3\n"
     "element vertex 12\nproperty float x\nproperty float y\nproperty float z\n"
     "property float nx\nproperty float ny\nproperty float nz\nend_header\n"},
    {"photoneo",
     "ply\nformat binary_little_endian 1.0\nobj_info Photoneo PLY PointCloud ( Width = 4; Height = 3)\n"
     "element vertex 12\nproperty float x\nproperty float y\nproperty float z\nend_header\n"},
}};

}  // namespace pyrseg::fuzz
