// PNG write -> read round trips, libpng's view of broken files, and the shared 16-bit depth image.
#include <random>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

TEST(Png, RgbRoundTrip) {
    ScratchDir dir;
    const int w = 13, h = 7;  // odd sizes: no row happens to be a multiple of anything
    std::vector<std::uint8_t> rgb(3 * w * h);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 37 + 11);
    write_png_rgb(dir / "c.png", rgb.data(), w, h);
    EXPECT_EQ(read_bytes(dir / "c.png").substr(1, 3), "PNG");
    const Image img = read_png(dir / "c.png");
    EXPECT_EQ(img.width, w);
    EXPECT_EQ(img.height, h);
    EXPECT_EQ(img.channels, 3);
    EXPECT_EQ(img.bit_depth, 8);
    EXPECT_EQ(img.data, rgb);
}

TEST(Png, Gray8RoundTrip) {
    ScratchDir dir;
    const int w = 256, h = 3;
    std::vector<std::uint8_t> gray(w * h);
    for (std::size_t i = 0; i < gray.size(); ++i) gray[i] = static_cast<std::uint8_t>(i);
    write_png_gray8(dir / "g.png", gray.data(), w, h);
    const Image img = read_png(dir / "g.png");
    EXPECT_EQ(img.width, w);
    EXPECT_EQ(img.height, h);
    EXPECT_EQ(img.channels, 1);
    EXPECT_EQ(img.bit_depth, 8);
    EXPECT_EQ(img.data, gray);
}

TEST(Png, Gray16RoundTripInHostOrder) {
    ScratchDir dir;
    const int w = 9, h = 5;
    std::vector<std::uint16_t> gray(w * h);
    for (std::size_t i = 0; i < gray.size(); ++i) gray[i] = static_cast<std::uint16_t>(i * 1499 + 1);
    gray[0] = 0;
    gray[1] = 65535;
    gray[2] = 256;
    gray[3] = 1;
    write_png_gray16(dir / "d.png", gray.data(), w, h);
    const Image img = read_png(dir / "d.png");
    EXPECT_EQ(img.width, w);
    EXPECT_EQ(img.height, h);
    EXPECT_EQ(img.channels, 1);
    EXPECT_EQ(img.bit_depth, 16);
    ASSERT_EQ(img.data.size(), gray.size() * 2);
    std::vector<std::uint16_t> back(gray.size());
    std::memcpy(back.data(), img.data.data(), img.data.size());
    // Writer and reader agree; SharedDepthImage checks the reader's byte order against a file made elsewhere.
    EXPECT_EQ(back, gray);
}

TEST(Png, BrokenFilesFailCleanly) {
    ScratchDir dir;
    std::vector<std::uint8_t> rgb(3 * 20 * 10, 128);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i ^ (i >> 3));
    write_png_rgb(dir / "ok.png", rgb.data(), 20, 10);
    const std::string full = read_bytes(dir / "ok.png");
    for (std::size_t cut = 0; cut < full.size(); ++cut) {
        write_bytes(dir / "cut.png", full.substr(0, cut));
        std::string message;
        ErrorCode code{};
        ASSERT_EQ(outcome([&] { read_png(dir / "cut.png"); }, &message, &code), "error") << cut;
        EXPECT_EQ(code, ErrorCode::format);
        EXPECT_NE(message.find("cut.png: "), std::string::npos) << message;
    }
    std::mt19937 rng(5u);
    int failed = 0;
    for (int trial = 0; trial < 200; ++trial) {
        std::string bytes = full;
        const std::size_t pos = rng() % bytes.size();
        bytes[pos] = static_cast<char>(bytes[pos] ^ static_cast<char>(1 + rng() % 255));
        write_bytes(dir / "flip.png", bytes);
        const std::string r = outcome([&] { read_png(dir / "flip.png"); });
        ASSERT_NE(r, "other") << trial;
        failed += r == "error";
    }
    EXPECT_GT(failed, 100);  // CRCs catch nearly every flip

    std::string message;
    write_bytes(dir / "text.png", "hello");
    EXPECT_EQ(outcome([&] { read_png(dir / "text.png"); }, &message), "error");
    EXPECT_NE(message.find("not a PNG file"), std::string::npos) << message;
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { read_png(dir / "none.png"); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
    EXPECT_EQ(outcome([&] { read_png(dir.path()); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
}

// A tiny file claiming a huge image: refused from its header, before anything is allocated for the pixels. Beyond
// any image size pyrseg reads (1,000,000 x 1,000,000, libpng's own limit), or within it (16000 x 16000) but more
// than deflate could have stored in the file.
TEST(Png, HugeDimensionsInTinyFileDoNotAllocate) {
    ScratchDir dir;
    std::vector<std::uint8_t> gray(4, 0);
    write_png_gray8(dir / "g.png", gray.data(), 2, 2);
    const std::string small = read_bytes(dir / "g.png");
    const auto claiming = [&](std::uint32_t side) {
        std::string bytes = small;
        // IHDR data sits at bytes 16..28: the width and height, then the CRC fixed.
        for (int k = 0; k < 4; ++k) {
            bytes[16 + k] = static_cast<char>(side >> (24 - 8 * k));
            bytes[20 + k] = static_cast<char>(side >> (24 - 8 * k));
        }
        std::uint32_t crc = 0xFFFFFFFFu;
        for (std::size_t i = 12; i < 29; ++i) {
            crc ^= static_cast<unsigned char>(bytes[i]);
            for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
        crc = ~crc;
        for (int k = 0; k < 4; ++k) bytes[29 + k] = static_cast<char>(crc >> (24 - 8 * k));
        return bytes;
    };
    write_bytes(dir / "huge.png", claiming(1000000));
    std::string message;
    EXPECT_EQ(outcome([&] { read_png(dir / "huge.png"); }, &message), "error");
    EXPECT_NE(message.find("PNG size 1000000 x 1000000 is not an image size pyrseg reads"), std::string::npos)
        << message;
    write_bytes(dir / "large.png", claiming(16000));
    EXPECT_EQ(outcome([&] { read_png(dir / "large.png"); }, &message), "error");
    EXPECT_NE(message.find("16000 x 16000 image cannot be stored in a file of"), std::string::npos) << message;
}

TEST(Png, WriteRejectsBadArguments) {
    ScratchDir dir;
    const std::uint8_t px[3] = {1, 2, 3};
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { write_png_rgb(dir / "x.png", nullptr, 1, 1); }, nullptr, &code), "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
    EXPECT_EQ(outcome([&] { write_png_gray8(dir / "x.png", px, 0, 1); }, nullptr, &code), "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
    EXPECT_EQ(outcome([&] { write_png_gray8(dir / "x.png", px, 3000000, 1); }, nullptr, &code), "error");
    EXPECT_EQ(outcome([&] { write_png_gray8(dir / "no" / "x.png", px, 1, 1); }, nullptr, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
}

TEST(Png, SharedDepthImage) {
    const fs::path path = fs::path(PYRSEG_SHARED_DATA_DIR) / "cape_depth_0.png";
    if (!fs::exists(path)) GTEST_SKIP() << "shared sample data not found: " << path;
    const Image img = read_png(path);
    EXPECT_EQ(img.width, 640);
    EXPECT_EQ(img.height, 480);
    EXPECT_EQ(img.channels, 1);
    EXPECT_EQ(img.bit_depth, 16);
    std::size_t valid = 0;
    std::uint16_t lo = 65535, hi = 0;
    for (std::size_t i = 0; i < 640 * 480; ++i) {
        std::uint16_t d = 0;
        std::memcpy(&d, &img.data[2 * i], 2);
        if (d == 0) continue;
        ++valid;
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    }
    EXPECT_GT(valid, 640u * 480u / 2);
    EXPECT_GT(lo, 300);    // millimetres: nothing nearer than 0.3 m
    EXPECT_LT(hi, 10000);  // nor farther than 10 m
}

}  // namespace
}  // namespace pyrseg::io::test
