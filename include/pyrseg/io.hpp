#pragma once
// pyrseg::io: the file formats the CLI and the tests need: PCD and PLY in; .npy, PNG and PLY out (and back in).
// Every failure is a pyrseg::Error whose message names the file: ErrorCode::io when the file cannot be opened,
// read or written, ErrorCode::format when its contents are malformed or unsupported, ErrorCode::out_of_memory when a
// well-formed file needs more memory than there is, ErrorCode::invalid_argument for bad arguments to a writer. No
// other exception leaves a reader, and a reader allocates only what the file can hold (a header that claims more
// than the file's bytes is a format error, found before the memory is taken). The writers of .npy, PNG, TIFF, PCD,
// PLY and statistics replace their file only once it is complete (a temporary file beside it, flushed, checked and
// renamed; PCL's PLY writer reports no write error, so its file is read back through read_ply's checks): a failure,
// a full disk included, is ErrorCode::io and leaves the old file or none, never a partial one.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "pyrseg/depth.hpp"
#include "pyrseg/io_export.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/scene.hpp"

namespace pyrseg::io {

// An organized cloud, packed, row-major: point (x, y) is points[3 * (y * width + x) + c].
struct PointCloud {
    int width = 0, height = 0;
    std::vector<float> points;   // 3*W*H xyz (NaN where invalid)
    std::vector<float> normals;  // 3*W*H, or empty when the file has no normal_x/normal_y/normal_z fields
};

enum class PcdEncoding { ascii, binary, binary_compressed };

// Reads a PCD v0.7 file (DATA ascii, binary or binary_compressed). Needs fields x y z (TYPE F, SIZE 4 or 8) and an
// organized cloud (HEIGHT > 1); normal_x normal_y normal_z are read when present, every other field is skipped.
// VIEWPOINT is ignored: points are returned in the file's frame.
PYRSEG_IO_EXPORT PointCloud read_pcd(const std::filesystem::path& path);

// Writes fields x y z (and normal_x normal_y normal_z when cloud.normals is not empty) as F 4, the way PCL does.
PYRSEG_IO_EXPORT void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, PcdEncoding encoding);
// The same with a `label` field (U 4) after them when labels (W*H, row-major) are given: PCL's PointXYZL layout
// (PointXYZLNormal's fields but curvature, with normals), which pcl::io::loadPCDFile reads into
// pcl::PointCloud<pcl::PointXYZL>. Label 0 is no segment.
PYRSEG_IO_EXPORT void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, const std::uint32_t* labels,
                                PcdEncoding encoding);
// A per-point unsigned integer field (U 4): W*H values, row-major.
struct PcdField {
    std::string name;  // one word of letters, digits and '_', not x, y, z or normal_*, and no other field's
    const std::uint32_t* values = nullptr;
};
// The same with any integer fields after the points (and normals), in the order given: {"label", labels} first
// gives pcl::PointXYZL's layout, and further fields (a segment's object, support or track) are read by name from
// pcl::PCLPointCloud2. A name that is not one word, is taken twice or has no values is pyrseg::Error
// (invalid_argument), and nothing is written.
PYRSEG_IO_EXPORT void write_pcd(const std::filesystem::path& path, const PointCloud& cloud,
                                std::span<const PcdField> fields, PcdEncoding encoding);

// PLY through PCL's PLY reader and writer (pcl_io). Without PCL at build time (PYRSEG_HAVE_PLY=0) both throw
// ErrorCode::format saying that pyrseg was built without PLY support.
//
// Reads ascii, binary_little_endian or binary_big_endian PLY: element vertex with x y z (float or double) and,
// when present, nx ny nz or normal_x normal_y normal_z (float or double); other properties and elements are
// skipped. The cloud must be organized, its grid given by one of: obj_info num_cols W / num_rows H (with or without
// a range_grid element mapping the W x H cells to vertices, as PCL's writer and the Stanford range scans store it;
// empty cells read as NaN), the camera element's viewportx / viewporty (PCL's writer with use_camera), or a
// Photoneo PhoXi header line "obj_info Photoneo PLY PointCloud ( Width = W; Height = H)". Points are returned as
// stored (PhoXi marks missing points as 0 0 0, which pyrseg's z > 0 rule treats as invalid).
PYRSEG_IO_EXPORT PointCloud read_ply(const std::filesystem::path& path);

// Writes an organized PLY that PCL, CloudCompare and MeshLab read: x y z, nx ny nz when cloud.normals is not empty,
// and red green blue (uchar) from label_color when labels (W*H, row-major) are given, label 0 as gray 128. Points
// with a non-finite coordinate are not written as vertices: obj_info num_cols/num_rows and a range_grid element
// keep the grid (PCL's organized layout), so viewers never see NaN vertices and read_ply returns them as NaN.
// Binary is exact; ascii has 6 significant digits (PCL's writer ignores its precision setting on this path).
PYRSEG_IO_EXPORT void write_ply(const std::filesystem::path& path, const PointCloud& cloud, const std::uint32_t* labels,
                                bool binary);

// NumPy .npy (format 1.0), C order, little-endian.
// '<u4' H x W, '|u1' H x W, '<f4' H x W x C (C=1: H x W).
PYRSEG_IO_EXPORT void write_npy(const std::filesystem::path& path, const std::uint32_t* data, int height, int width);
PYRSEG_IO_EXPORT void write_npy(const std::filesystem::path& path, const std::uint8_t* data, int height, int width);
PYRSEG_IO_EXPORT void write_npy(const std::filesystem::path& path, const float* data, int height, int width,
                                int channels);

struct NpyArray {
    std::string dtype;                 // numpy's descr, e.g. "<f4", "|u1"
    std::vector<std::size_t> shape;    // empty for a 0-d array
    std::vector<unsigned char> bytes;  // the array data, C order, as stored
};
// Format 1.0/2.0/3.0 headers, C order, little-endian or byte-order-free dtypes of kind b, i, u, f, c.
PYRSEG_IO_EXPORT NpyArray read_npy(const std::filesystem::path& path);

PYRSEG_IO_EXPORT void write_png_rgb(const std::filesystem::path& path, const std::uint8_t* rgb, int width, int height);
PYRSEG_IO_EXPORT void write_png_gray16(const std::filesystem::path& path, const std::uint16_t* gray, int width,
                                       int height);
PYRSEG_IO_EXPORT void write_png_gray8(const std::filesystem::path& path, const std::uint8_t* gray, int width,
                                      int height);

struct Image {
    int width = 0, height = 0, channels = 0, bit_depth = 0;
    std::vector<std::uint8_t> data;  // data as stored: 16-bit samples in host order
};
// Palette images come back as RGB (RGBA with transparency), gray below 8 bits as 8-bit; bit_depth is 8 or 16.
PYRSEG_IO_EXPORT Image read_png(const std::filesystem::path& path);

// An organized cloud stored as a NumPy array: H x W x 3 (points) or H x W x 6 (points, then normals), float32 or
// float64 ('<f4', '<f8'), C order.
PYRSEG_IO_EXPORT PointCloud read_npy_cloud(const std::filesystem::path& path);

// A depth image: one sample per pixel in the file's units, row-major. 0, NaN, infinite or negative: no data.
struct DepthImage {
    int width = 0, height = 0;
    std::vector<float> depth;
    bool floating = false;  // float samples (usually metres) rather than integers (usually millimetres)
};
// A 16-bit grayscale PNG (as depth cameras and TUM/CAPE datasets store millimetres or 1/5000 m), or a
// single-channel, stripped TIFF of 16-bit unsigned or 32-bit float samples (libtiff), at most 65536 pixels on a side
// and 2^28 pixels in all.
PYRSEG_IO_EXPORT DepthImage read_depth_image(const std::filesystem::path& path);
PYRSEG_IO_EXPORT void write_tiff_float(const std::filesystem::path& path, const float* depth, int width, int height);

// Pinhole intrinsics in pixels.
struct Intrinsics {
    double fx = 0, fy = 0, cx = 0, cy = 0;
};
// "fx,fy,cx,cy" (four numbers, fx and fy > 0). Throws ErrorCode::invalid_argument naming the problem.
PYRSEG_IO_EXPORT Intrinsics parse_intrinsics(const std::string& text);
// An OpenCV FileStorage file (XML, YAML or JSON), read by OpenCV. `node` names either a 3x3 camera matrix
// [fx 0 cx; 0 fy cy; 0 0 1] or a map with keys fx, fy, cx, cy. With an empty `node` the file's top level must hold
// fx fy cx cy, or exactly one 3x3 matrix. The message of a failure names the file and the node.
PYRSEG_IO_EXPORT Intrinsics read_intrinsics(const std::filesystem::path& path, const std::string& node = {});

// An organized cloud in millimetres from a depth image: z = depth * metres_per_unit * 1000, x = (u - cx) * z / fx,
// y = (v - cy) * z / fy (computed in double, stored as float); pixels without data are NaN. metres_per_unit is the
// depth of one sample unit in metres, as in DepthView (0.001 for millimetres); the camera is checked as
// pyrseg::check_depth_camera checks it (a wrong depth scale or intrinsics in the wrong order is an error).
PYRSEG_IO_EXPORT PointCloud depth_to_cloud(const DepthImage& image, const Intrinsics& k, double metres_per_unit);

// A DepthView of the image's samples (float32, as DepthImage holds them: a 16-bit image's integers are exact, and
// segment into the very labels their uint16 samples do), for Segmenter::segment; `image` must outlive the view.
// pyrseg.io.read_depth_image in Python gives the uint16 samples themselves.
[[nodiscard]] PYRSEG_IO_EXPORT DepthView depth_view(const DepthImage& image, const Intrinsics& k,
                                                    double metres_per_unit);

// Colour-coded segmentation: label 0 black, other labels distinct saturated colours (a fixed hash of the label so
// the same label is the same colour in every picture; neighbouring label values clearly different).
PYRSEG_IO_EXPORT std::array<std::uint8_t, 3> label_color(std::uint32_t label);
// 3*W*H RGB
PYRSEG_IO_EXPORT std::vector<std::uint8_t> colorize_labels(const std::uint32_t* labels, int width, int height);

// Per-segment statistics (Result::segments) as a table: CSV with a header line when the path ends in .csv, else
// JSON (nlohmann/json) with the frame's size and units, and one object per segment. Centroids are in the cloud's
// units (unit_mm millimetres each); NaN (a mask's missing geometry) is an empty CSV field and JSON null.
struct SegmentTable {
    int width = 0, height = 0;
    double unit_mm = 1.0;
    std::string source;  // the input file, written into the JSON
};
PYRSEG_IO_EXPORT void write_segment_stats(const std::filesystem::path& path, const std::vector<SegmentStats>& segments,
                                          const SegmentTable& frame);

// The segment graph (Result::graph): CSV with a header line when the path ends in .csv, else JSON with the frame's
// size and one object per pair of touching segments (a, b, length and the crossings of each kind).
PYRSEG_IO_EXPORT void write_segment_graph(const std::filesystem::path& path, const std::vector<SegmentEdge>& graph,
                                          const SegmentTable& frame);

// The scene summary (pyrseg/scene.hpp): JSON with the frame's size and units, its supports (plane, box) and objects
// (support, height, box), lengths in the cloud's units; or, when the path ends in .ply, an ASCII PLY mesh of each
// object's box (12 triangles) and each support's outline (its box's rectangle in its plane, 2 triangles), coloured
// as label_color colours the segments, for CloudCompare or MeshLab beside the cloud's PLY.
PYRSEG_IO_EXPORT void write_scene(const std::filesystem::path& path, const Scene& scene, const SegmentTable& frame);

}  // namespace pyrseg::io
