// .npy writing (checked byte for byte against what numpy expects) and reading.
#include <numeric>
#include <random>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

struct RawNpy {
    int major = 0, minor = 0;
    std::string dict;  // the header text, padding and newline included
    std::string data;
};

RawNpy split_npy(const std::string& bytes) {
    RawNpy r;
    EXPECT_GE(bytes.size(), 10u);
    if (bytes.size() < 10) return r;
    EXPECT_EQ(bytes.substr(0, 6), std::string("\x93NUMPY", 6));
    r.major = static_cast<unsigned char>(bytes[6]);
    r.minor = static_cast<unsigned char>(bytes[7]);
    const std::size_t len =
        static_cast<unsigned char>(bytes[8]) | static_cast<std::size_t>(static_cast<unsigned char>(bytes[9])) << 8;
    r.dict = bytes.substr(10, len);
    r.data = bytes.substr(10 + len);
    return r;
}

void expect_numpy_header(const std::string& bytes, const std::string& dict_start) {
    const RawNpy r = split_npy(bytes);
    EXPECT_EQ(r.major, 1);
    EXPECT_EQ(r.minor, 0);
    EXPECT_EQ((10 + r.dict.size()) % 64, 0u) << "data must start on a 64-byte boundary";
    ASSERT_FALSE(r.dict.empty());
    EXPECT_EQ(r.dict.back(), '\n');
    EXPECT_EQ(r.dict.substr(0, dict_start.size()), dict_start);
    const std::string padding = r.dict.substr(dict_start.size(), r.dict.size() - dict_start.size() - 1);
    EXPECT_EQ(padding.find_first_not_of(' '), std::string::npos) << "padding is spaces only: '" << padding << "'";
}

TEST(Npy, Uint32LabelsRoundTrip) {
    ScratchDir dir;
    const int h = 3, w = 5;
    std::vector<std::uint32_t> labels(h * w);
    std::iota(labels.begin(), labels.end(), 4294967280u);
    write_npy(dir / "labels.npy", labels.data(), h, w);
    const std::string bytes = read_bytes(dir / "labels.npy");
    expect_numpy_header(bytes, "{'descr': '<u4', 'fortran_order': False, 'shape': (3, 5), }");
    const RawNpy raw = split_npy(bytes);
    ASSERT_EQ(raw.data.size(), labels.size() * 4);
    EXPECT_EQ(std::memcmp(raw.data.data(), labels.data(), raw.data.size()), 0);  // little-endian, C order

    const NpyArray a = read_npy(dir / "labels.npy");
    EXPECT_EQ(a.dtype, "<u4");
    EXPECT_EQ(a.shape, (std::vector<std::size_t>{3, 5}));
    ASSERT_EQ(a.bytes.size(), labels.size() * 4);
    EXPECT_EQ(std::memcmp(a.bytes.data(), labels.data(), a.bytes.size()), 0);
}

TEST(Npy, Uint8MasksRoundTrip) {
    ScratchDir dir;
    const int h = 4, w = 3;
    const std::vector<std::uint8_t> mask = {0, 1, 1, 0, 255, 0, 1, 1, 1, 0, 0, 7};
    write_npy(dir / "mask.npy", mask.data(), h, w);
    const std::string bytes = read_bytes(dir / "mask.npy");
    expect_numpy_header(bytes, "{'descr': '|u1', 'fortran_order': False, 'shape': (4, 3), }");
    const RawNpy raw = split_npy(bytes);
    ASSERT_EQ(raw.data.size(), mask.size());
    EXPECT_EQ(std::memcmp(raw.data.data(), mask.data(), mask.size()), 0);
    const NpyArray a = read_npy(dir / "mask.npy");
    EXPECT_EQ(a.dtype, "|u1");
    EXPECT_EQ(a.shape, (std::vector<std::size_t>{4, 3}));
    EXPECT_EQ(a.bytes, std::vector<unsigned char>(mask.begin(), mask.end()));
}

TEST(Npy, FloatImagesRoundTrip) {
    ScratchDir dir;
    for (const int channels : {1, 3, 4}) {
        SCOPED_TRACE(channels);
        const int h = 7, w = 2;
        std::vector<float> values(static_cast<std::size_t>(h * w * channels));
        for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i) * 0.5f - 3.0f;
        values[1] = std::numeric_limits<float>::quiet_NaN();
        write_npy(dir / "f.npy", values.data(), h, w, channels);
        const std::string bytes = read_bytes(dir / "f.npy");
        const std::string shape = channels == 1 ? "(7, 2)" : "(7, 2, " + std::to_string(channels) + ")";
        expect_numpy_header(bytes, "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }");
        const NpyArray a = read_npy(dir / "f.npy");
        EXPECT_EQ(a.dtype, "<f4");
        std::vector<std::size_t> expected_shape = {7, 2};
        if (channels > 1) expected_shape.push_back(static_cast<std::size_t>(channels));
        EXPECT_EQ(a.shape, expected_shape);
        ASSERT_EQ(a.bytes.size(), values.size() * 4);
        EXPECT_EQ(std::memcmp(a.bytes.data(), values.data(), a.bytes.size()), 0);
    }
}

TEST(Npy, HeaderPaddingForEveryLength) {
    // Shapes with more digits move the padding boundary; the data offset must stay a multiple of 64.
    ScratchDir dir;
    std::vector<std::uint32_t> data(100000);
    for (const auto& [h, w] : std::vector<std::pair<int, int>>{{1, 1}, {10, 10}, {100, 1000}, {1, 99999}, {99999, 1}}) {
        write_npy(dir / "p.npy", data.data(), h, w);
        const std::string bytes = read_bytes(dir / "p.npy");
        expect_numpy_header(bytes, "{'descr': '<u4', 'fortran_order': False, 'shape': (" + std::to_string(h) + ", " +
                                       std::to_string(w) + "), }");
        EXPECT_EQ(read_npy(dir / "p.npy").bytes.size(), static_cast<std::size_t>(h) * w * 4);
    }
}

std::string npy_file(int major, const std::string& dict, std::size_t data_bytes) {
    std::string s("\x93NUMPY", 6);
    s += static_cast<char>(major);
    s += '\0';
    const std::size_t len = dict.size();
    s += static_cast<char>(len & 0xff);
    s += static_cast<char>((len >> 8) & 0xff);
    if (major >= 2) s += std::string(2, '\0');
    return s + dict + std::string(data_bytes, '\x01');
}

TEST(Npy, ReadsWhatOtherNumpyVersionsWrite) {
    ScratchDir dir;
    // Version 2.0, double quotes, keys in another order, Python 2 longs, no trailing comma, a 1-D shape.
    write_bytes(dir / "v2.npy", npy_file(2, "{\"shape\": (6L,), \"fortran_order\": False, \"descr\": \"|u1\"}\n", 6));
    NpyArray a = read_npy(dir / "v2.npy");
    EXPECT_EQ(a.dtype, "|u1");
    EXPECT_EQ(a.shape, std::vector<std::size_t>{6});
    EXPECT_EQ(a.bytes.size(), 6u);
    // A 0-d array and an empty one.
    write_bytes(dir / "s.npy", npy_file(1, "{'descr': '<f8', 'fortran_order': False, 'shape': (), }\n", 8));
    a = read_npy(dir / "s.npy");
    EXPECT_TRUE(a.shape.empty());
    EXPECT_EQ(a.bytes.size(), 8u);
    write_bytes(dir / "e.npy", npy_file(1, "{'descr': '<i2', 'fortran_order': False, 'shape': (0, 4), }\n", 0));
    EXPECT_EQ(read_npy(dir / "e.npy").shape, (std::vector<std::size_t>{0, 4}));
}

TEST(Npy, MalformedFilesFailCleanly) {
    ScratchDir dir;
    const std::string ok = "{'descr': '<u4', 'fortran_order': False, 'shape': (2, 3), }\n";
    const std::pair<std::string, std::string> cases[] = {
        {"not numpy at all", "not a .npy file"},
        {npy_file(4, ok, 24), "npy format version 4.0 is not supported"},
        {npy_file(1, ok, 23), "needs 24 bytes of data, the file has 23"},
        {npy_file(1, ok, 25), "needs 24 bytes of data, the file has 25"},
        {npy_file(1, ok, 24).substr(0, 40), "exceeds"},
        {npy_file(1, "{'descr': '>u4', 'fortran_order': False, 'shape': (2, 3), }\n", 24), "dtype '>u4'"},
        {npy_file(1, "{'descr': '<U4', 'fortran_order': False, 'shape': (2, 3), }\n", 24), "dtype '<U4'"},
        {npy_file(1, "{'descr': '<u3', 'fortran_order': False, 'shape': (2, 3), }\n", 18), "dtype '<u3'"},
        {npy_file(1, "{'descr': [('a', '<u4')], 'fortran_order': False, 'shape': (2,), }\n", 8), "structured"},
        {npy_file(1, "{'descr': '<u4', 'fortran_order': True, 'shape': (2, 3), }\n", 24), "C order"},
        {npy_file(1, "{'descr': '<u4', 'fortran_order': False}\n", 24), "needs the keys"},
        {npy_file(1, "{'descr': '<u4', 'fortran_order': False, 'shape': (2, 3), 'x': 1}\n", 24), "key 'x'"},
        {npy_file(1, "{'descr': '<u4', 'descr': '<u4', 'fortran_order': False, 'shape': (2, 3)}\n", 24),
         "repeated key 'descr'"},
        {npy_file(1, "{'descr': '<u4', 'fortran_order': False, 'shape': (2, -3), }\n", 24), "malformed 'shape'"},
        {npy_file(1, "{'descr': '<u4', 'fortran_order': False, 'shape': (2, 3), }x\n", 24), "after the header"},
        {npy_file(1, "{'descr': '<u4, 'fortran_order': False, 'shape': (2, 3), }\n", 24), "malformed header"},
        {npy_file(1, "{'descr': '<u4', 'fortran_order': False, 'shape': (4294967296, 4294967296, 16), }\n", 0),
         "overflows"},
        {npy_file(1, "{'descr': '<u1', 'fortran_order': False, 'shape': (100000, 100000), }\n", 10),
         "needs 10000000000 bytes of data, the file has 10 (truncated file?)"},
    };
    for (const auto& [bytes, expected] : cases) {
        write_bytes(dir / "bad.npy", bytes);
        std::string message;
        ErrorCode code{};
        ASSERT_EQ(outcome([&] { read_npy(dir / "bad.npy"); }, &message, &code), "error") << expected;
        EXPECT_EQ(code, ErrorCode::format);
        EXPECT_NE(message.find("bad.npy: "), std::string::npos) << message;
        EXPECT_NE(message.find(expected), std::string::npos) << "'" << expected << "' not in: " << message;
    }
    std::string message;
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { read_npy(dir / "none.npy"); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
}

TEST(Npy, TruncationsAndFlipsFailCleanly) {
    ScratchDir dir;
    std::vector<float> values(2 * 3 * 3, 1.25f);
    write_npy(dir / "a.npy", values.data(), 2, 3, 3);
    const std::string full = read_bytes(dir / "a.npy");
    for (std::size_t cut = 0; cut < full.size(); ++cut) {
        write_bytes(dir / "t.npy", full.substr(0, cut));
        EXPECT_EQ(outcome([&] { read_npy(dir / "t.npy"); }), "error") << cut;
    }
    std::mt19937 rng(99u);
    for (int trial = 0; trial < 200; ++trial) {
        std::string bytes = full;
        const std::size_t pos = rng() % 64;
        bytes[pos] = static_cast<char>(bytes[pos] ^ static_cast<char>(1 + rng() % 255));
        write_bytes(dir / "f.npy", bytes);
        ASSERT_NE(outcome([&] { read_npy(dir / "f.npy"); }), "other") << trial;
    }
}

TEST(Npy, WriteRejectsBadArguments) {
    ScratchDir dir;
    const std::uint32_t one = 1;
    ErrorCode code{};
    EXPECT_EQ(
        outcome([&] { write_npy(dir / "x.npy", static_cast<const std::uint32_t*>(nullptr), 2, 2); }, nullptr, &code),
        "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
    EXPECT_EQ(outcome([&] { write_npy(dir / "x.npy", &one, 0, 1); }), "error");
    EXPECT_EQ(outcome([&] { write_npy(dir / "x.npy", reinterpret_cast<const float*>(&one), 1, 1, 0); }), "error");
    EXPECT_EQ(outcome([&] { write_npy(dir / "no" / "x.npy", &one, 1, 1); }, nullptr, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
}

}  // namespace
}  // namespace pyrseg::io::test
