// Depth images (16-bit PNG, float and 16-bit TIFF), pinhole intrinsics (flags and OpenCV FileStorage files) and the
// back-projection to an organized cloud in millimetres.
#include <gtest/gtest.h>

#include <filesystem>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::io::test {
namespace {

template <class F>
ErrorCode error_of(F&& f, std::string* message = nullptr) {
    try {
        f();
    } catch (const Error& e) {
        if (message != nullptr) *message = e.what();
        return e.code();
    }
    ADD_FAILURE() << "expected a pyrseg::Error";
    return ErrorCode::internal;
}

TEST(DepthImage, SixteenBitPngRoundTrips) {
    ScratchDir dir;
    const int w = 7;
    const int h = 5;
    std::vector<std::uint16_t> raw(std::size_t(w) * h);
    for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = std::uint16_t(i * 1237 % 65536);
    write_png_gray16(dir / "d.png", raw.data(), w, h);
    const DepthImage d = read_depth_image(dir / "d.png");
    ASSERT_EQ(d.width, w);
    ASSERT_EQ(d.height, h);
    EXPECT_FALSE(d.floating);
    for (std::size_t i = 0; i < raw.size(); ++i) EXPECT_EQ(d.depth[i], float(raw[i])) << i;
}

TEST(DepthImage, FloatTiffRoundTripsBitForBit) {
    ScratchDir dir;
    const int w = 9;
    const int h = 4;
    std::vector<float> depth(std::size_t(w) * h);
    for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = 0.5f + float(i) * 0.0173f;
    depth[3] = std::numeric_limits<float>::quiet_NaN();
    depth[4] = 0.0f;
    write_tiff_float(dir / "d.tiff", depth.data(), w, h);
    const DepthImage d = read_depth_image(dir / "d.tiff");
    ASSERT_EQ(d.width, w);
    ASSERT_EQ(d.height, h);
    EXPECT_TRUE(d.floating);
    EXPECT_EQ(0, std::memcmp(d.depth.data(), depth.data(), depth.size() * sizeof(float)));
}

TEST(DepthImage, ImagesThatAreNotDepthAreRefusedNamingTheFile) {
    ScratchDir dir;
    const std::vector<std::uint8_t> gray(12, 9);
    write_png_gray8(dir / "eight.png", gray.data(), 4, 3);
    std::string message;
    EXPECT_EQ(error_of([&] { (void)read_depth_image(dir / "eight.png"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("eight.png"), std::string::npos) << message;
    EXPECT_NE(message.find("16-bit grayscale"), std::string::npos) << message;
    EXPECT_EQ(error_of([&] { (void)read_depth_image(dir / "missing.png"); }), ErrorCode::io);
    EXPECT_EQ(error_of([&] { (void)read_depth_image(dir / "d.jpg"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("unsupported depth image format"), std::string::npos) << message;
}

// Every prefix of a valid TIFF, and byte flips in it: an error or a well-formed image, never a crash.
TEST(DepthImage, TruncatedAndCorruptTiffsGiveErrorsNotCrashes) {
    ScratchDir dir;
    std::vector<float> depth(64, 1.25f);
    write_tiff_float(dir / "good.tif", depth.data(), 8, 8);
    const std::string good = read_bytes(dir / "good.tif");
    int errors = 0;
    for (std::size_t cut = 0; cut < good.size(); cut += 7) {
        write_bytes(dir / "cut.tif", good.substr(0, cut));
        try {
            const DepthImage d = read_depth_image(dir / "cut.tif");
            EXPECT_EQ(d.depth.size(), std::size_t(d.width) * std::size_t(d.height));
        } catch (const Error& e) {
            ++errors;
            EXPECT_NE(std::string(e.what()).find("cut.tif"), std::string::npos) << e.what();
        }
    }
    EXPECT_GT(errors, 0);
    for (std::size_t at = 0; at < good.size(); at += 3) {
        std::string bad = good;
        bad[at] = char(bad[at] ^ 0x5a);
        write_bytes(dir / "flip.tif", bad);
        try {
            const DepthImage d = read_depth_image(dir / "flip.tif");
            EXPECT_EQ(d.depth.size(), std::size_t(d.width) * std::size_t(d.height));
        } catch (const Error&) {
        }
    }
}

TEST(DepthToCloud, BackProjectsThroughThePinholeModelInMillimetres) {
    DepthImage d{3, 2, {1000, 0, 2000, std::numeric_limits<float>::quiet_NaN(), -5, 500}, false};
    const Intrinsics k{500.0, 400.0, 1.0, 0.0};
    const PointCloud c = depth_to_cloud(d, k, 0.0002);  // TUM: 5000 units per metre
    ASSERT_EQ(c.width, 3);
    ASSERT_EQ(c.height, 2);
    // (u, v) = (0, 0), 1000 units = 200 mm: x = (0 - 1) * 200 / 500, y = 0.
    EXPECT_FLOAT_EQ(c.points[0], -0.4f);
    EXPECT_FLOAT_EQ(c.points[1], 0.0f);
    EXPECT_FLOAT_EQ(c.points[2], 200.0f);
    for (int i : {1, 3, 4}) EXPECT_TRUE(std::isnan(c.points[3 * std::size_t(i) + 2])) << "pixel " << i;
    // (2, 1), 500 units = 100 mm: x = (2 - 1) * 100 / 500, y = (1 - 0) * 100 / 400.
    EXPECT_FLOAT_EQ(c.points[15], 0.2f);
    EXPECT_FLOAT_EQ(c.points[16], 0.25f);
    EXPECT_FLOAT_EQ(c.points[17], 100.0f);
    EXPECT_EQ(error_of([&] { (void)depth_to_cloud(d, Intrinsics{0, 1, 0, 0}, 0.001); }), ErrorCode::invalid_parameter);
    EXPECT_EQ(error_of([&] { (void)depth_to_cloud(d, k, 0.0); }), ErrorCode::invalid_parameter);
}

TEST(DepthToCloud, ChecksTheCameraAsTheSegmenterDoes) {
    DepthImage image{640, 480, std::vector<float>(640 * 480, 800.0f), false};
    const Intrinsics k{612.937, 613.173, 322.549, 248.158};
    const PointCloud cloud = depth_to_cloud(image, k, 0.001);
    EXPECT_FLOAT_EQ(cloud.points[2], 800.0f);
    try {
        (void)depth_to_cloud(image, k, 1.0);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("metres_per_unit 0.001 makes it 0.8 m"), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)depth_to_cloud(image, Intrinsics{322.549, 248.158, 612.937, 613.173}, 0.001), Error);
}

// C++ reads a 16-bit depth PNG as floats, Python as uint16: depth_view's float samples segment into the very labels
// the uint16 samples do, so both routes agree byte for byte.
TEST(DepthView, AReadImageSegmentsAsItsSixteenBitSamples) {
    ScratchDir dir;
    const int w = 64, h = 48;
    std::vector<std::uint16_t> mm(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) mm[std::size_t(y * w + x)] = std::uint16_t(x < w / 2 ? 800 + y : 1200 - x);
    }
    write_png_gray16(dir / "d.png", mm.data(), w, h);
    const DepthImage image = read_depth_image(dir / "d.png");
    const Intrinsics k{60.0, 60.0, 32.0, 24.0};
    Segmenter segmenter(w, h, Params{}, "cpu");
    const Result from_floats = segmenter.segment(depth_view(image, k, 0.001));
    const Result from_u16 =
        segmenter.segment(DepthView{mm.data(), DepthFormat::u16, w, h, 0, 0.001, k.fx, k.fy, k.cx, k.cy});
    EXPECT_GT(from_u16.segment_count, 1u);
    EXPECT_EQ(from_floats.labels, from_u16.labels);
}

TEST(Intrinsics, ParsedFromFourNumbers) {
    const Intrinsics k = parse_intrinsics("575.9,576.4,315.15,230.59");
    EXPECT_DOUBLE_EQ(k.fx, 575.9);
    EXPECT_DOUBLE_EQ(k.fy, 576.4);
    EXPECT_DOUBLE_EQ(k.cx, 315.15);
    EXPECT_DOUBLE_EQ(k.cy, 230.59);
    for (const char* bad : {"", "1,2,3", "1,2,3,4,5", "1,2,x,4", "0,1,2,3", "1,-1,2,3", "1,2,3,4 ", "nan,1,2,3"}) {
        EXPECT_EQ(error_of([&] { (void)parse_intrinsics(bad); }), ErrorCode::invalid_argument) << bad;
    }
}

constexpr const char* kTwoMatricesXml = R"(<?xml version="1.0"?>
<opencv_storage>
<RGB type_id="opencv-matrix"><rows>3</rows><cols>3</cols><dt>d</dt>
  <data>500. 0. 320. 0. 501. 240. 0. 0. 1.</data></RGB>
<IR type_id="opencv-matrix"><rows>3</rows><cols>3</cols><dt>d</dt>
  <data>575.5 0. 315.25 0. 576.5 230.75 0. 0. 1.</data></IR>
<Distortion type_id="opencv-matrix"><rows>1</rows><cols>5</cols><dt>d</dt><data>0. 0. 0. 0. 0.</data></Distortion>
</opencv_storage>
)";

TEST(Intrinsics, ReadFromOpenCvFileStorage) {
    ScratchDir dir;
    write_bytes(dir / "two.xml", kTwoMatricesXml);
    const Intrinsics ir = read_intrinsics(dir / "two.xml", "IR");
    EXPECT_DOUBLE_EQ(ir.fx, 575.5);
    EXPECT_DOUBLE_EQ(ir.fy, 576.5);
    EXPECT_DOUBLE_EQ(ir.cx, 315.25);
    EXPECT_DOUBLE_EQ(ir.cy, 230.75);
    std::string message;
    EXPECT_EQ(error_of([&] { (void)read_intrinsics(dir / "two.xml"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("RGB, IR"), std::string::npos) << message;
    EXPECT_EQ(error_of([&] { (void)read_intrinsics(dir / "two.xml", "Depth"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("no node 'Depth'"), std::string::npos) << message;
    EXPECT_EQ(error_of([&] { (void)read_intrinsics(dir / "two.xml", "Distortion"); }), ErrorCode::format);

    write_bytes(dir / "small.yaml", "%YAML:1.0\n---\nfx: 520.5\nfy: 521.0\ncx: 319.5\ncy: 239.5\n");
    const Intrinsics y = read_intrinsics(dir / "small.yaml");
    EXPECT_DOUBLE_EQ(y.fx, 520.5);
    EXPECT_DOUBLE_EQ(y.cy, 239.5);

    write_bytes(dir / "garbage.xml", "<not closed");
    EXPECT_EQ(error_of([&] { (void)read_intrinsics(dir / "garbage.xml"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("garbage.xml"), std::string::npos) << message;
    EXPECT_EQ(error_of([&] { (void)read_intrinsics(dir / "none.xml"); }), ErrorCode::io);
}

TEST(Intrinsics, TheSharedCapeCalibrationGivesTheIrCamera) {
    const fs::path calib = fs::path(PYRSEG_SHARED_DATA_DIR) / "cape_calib_params.xml";
    if (!fs::exists(calib)) GTEST_SKIP() << "sample calibration not present: " << calib.string();
    const Intrinsics k = read_intrinsics(calib, "IR_intrinsic_params");
    EXPECT_NEAR(k.fx, 575.93, 0.01);
    EXPECT_NEAR(k.fy, 576.41, 0.01);
    EXPECT_NEAR(k.cx, 315.15, 0.01);
    EXPECT_NEAR(k.cy, 230.59, 0.01);
}

}  // namespace
}  // namespace pyrseg::io::test

namespace pyrseg::io::test {
namespace {

// A '<f8' .npy written by hand (pyrseg's writer only writes float32), the way numpy.save lays it out.
std::string npy_f8(const std::vector<double>& values, const std::string& shape, const std::string& descr = "<f8") {
    std::string header = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string out = "\x93NUMPY";
    out += '\x01';
    out += '\x00';
    out += char(header.size() & 0xff);
    out += char(header.size() >> 8);
    out += header;
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
    return out;
}

TEST(NpyCloud, PointsAndNormalsRoundTrip) {
    ScratchDir dir;
    const int w = 4;
    const int h = 3;
    std::vector<float> six(std::size_t(w) * h * 6);
    for (std::size_t i = 0; i < six.size(); ++i) six[i] = float(i) * 0.25f - 3.0f;
    write_npy(dir / "six.npy", six.data(), h, w, 6);
    const PointCloud c = read_npy_cloud(dir / "six.npy");
    ASSERT_EQ(c.width, w);
    ASSERT_EQ(c.height, h);
    ASSERT_EQ(c.normals.size(), c.points.size());
    for (std::size_t i = 0; i < std::size_t(w) * h; ++i) {
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_EQ(c.points[3 * i + k], six[6 * i + k]);
            EXPECT_EQ(c.normals[3 * i + k], six[6 * i + 3 + k]);
        }
    }
    write_npy(dir / "three.npy", six.data(), h, w * 2, 3);
    const PointCloud p = read_npy_cloud(dir / "three.npy");
    EXPECT_EQ(p.width, 2 * w);
    EXPECT_TRUE(p.normals.empty());
    EXPECT_EQ(0, std::memcmp(p.points.data(), six.data(), six.size() * sizeof(float)));
    write_bytes(dir / "f8.npy", npy_f8({1.5, -2.25, 1000.0, 0.0, 0.0, 1e-3}, "(1, 2, 3)"));
    const PointCloud d = read_npy_cloud(dir / "f8.npy");
    ASSERT_EQ(d.width, 2);
    EXPECT_EQ(d.points[1], -2.25f);
    EXPECT_EQ(d.points[5], 1e-3f);
}

TEST(NpyCloud, ArraysThatAreNotCloudsAreRefusedNamingTheShape) {
    ScratchDir dir;
    const std::vector<std::uint32_t> labels(12, 1);
    write_npy(dir / "labels.npy", labels.data(), 3, 4);
    std::string message;
    EXPECT_EQ(error_of([&] { (void)read_npy_cloud(dir / "labels.npy"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("this one is 3 x 4"), std::string::npos) << message;
    const std::vector<float> four(3 * 4 * 4, 1.0f);
    write_npy(dir / "four.npy", four.data(), 3, 4, 4);
    EXPECT_EQ(error_of([&] { (void)read_npy_cloud(dir / "four.npy"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("3 x 4 x 4"), std::string::npos) << message;
    write_bytes(dir / "i8.npy", npy_f8({1, 2, 3}, "(1, 1, 3)", "<i8"));
    EXPECT_EQ(error_of([&] { (void)read_npy_cloud(dir / "i8.npy"); }, &message), ErrorCode::format);
    EXPECT_NE(message.find("'<i8'"), std::string::npos) << message;
}

}  // namespace
}  // namespace pyrseg::io::test
