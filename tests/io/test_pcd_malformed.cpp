// Malformed PCD files: each must load or throw pyrseg::Error naming the file, never crash, hang or read out of
// bounds (run under -DPYRSEG_SANITIZE=ON to check the last).
#include <chrono>
#include <random>
#include <sstream>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

const std::vector<FieldSpec> kXyzRgba = {{"x"}, {"y"}, {"z"}, {"rgba", 'U', 4, 1}};
constexpr int kW = 5, kH = 4;

std::vector<std::vector<double>> xyz_rgba_values(int n) {
    std::vector<std::vector<double>> v;
    for (int i = 0; i < n; ++i) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const bool invalid = i % 6 == 1;
        v.push_back(
            {invalid ? nan : i * 0.125, invalid ? nan : -i * 0.5, invalid ? nan : 1.0 + i / 8.0, 4278190080.0 + i});
    }
    return v;
}

std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
    std::string s;
    for (const auto& l : lines) s += l + "\n";
    return s;
}

std::string expect_error(const fs::path& path, ErrorCode expected_code = ErrorCode::format) {
    return expect_load_error(
        path, [&] { read_pcd(path); }, expected_code);
}

void expect_error_containing(const fs::path& path, const std::string& text) {
    expect_load_error_containing(
        path, [&] { read_pcd(path); }, text);
}

class PcdMalformed : public ::testing::TestWithParam<std::string> {
protected:
    std::string encoding() const { return GetParam(); }
    std::vector<std::string> header_lines() const { return split_lines(pcd_header(kXyzRgba, kW, kH, encoding())); }
    std::string body() const { return pcd_body(kXyzRgba, xyz_rgba_values(kW * kH), encoding()); }
    ScratchDir dir;
};

TEST_P(PcdMalformed, ValidBaseFileLoads) {
    write_bytes(dir / "base.pcd", join_lines(header_lines()) + body());
    const PointCloud c = read_pcd(dir / "base.pcd");
    EXPECT_EQ(c.width, kW);
    EXPECT_EQ(c.height, kH);
    EXPECT_TRUE(c.normals.empty());
    EXPECT_EQ(c.points[3 * 4 + 2], 1.5f);
}

TEST_P(PcdMalformed, EveryHeaderLineBrokenInTurn) {
    const auto lines = header_lines();
    ASSERT_EQ(lines.size(), 11u);
    int cases = 0;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const std::string keyword = lines[i].substr(0, lines[i].find(' '));
        const bool comment = keyword == "#";
        const bool optional = comment || keyword == "COUNT" || keyword == "VIEWPOINT";
        // Whether the broken file must load (yes), must fail (no), or may do either (a duplicated DATA line in a
        // binary file just shifts the data, which binary cannot detect).
        enum Expect { yes, no, either };
        struct Variant {
            std::string name;
            std::vector<std::string> lines;
            Expect expect;
        };
        const Expect if_comment = comment ? yes : no;
        std::vector<Variant> variants;
        auto with = [&](const std::string& replacement) {
            auto l = lines;
            l[i] = replacement;
            return l;
        };
        auto erased = lines;
        erased.erase(erased.begin() + static_cast<std::ptrdiff_t>(i));
        variants.push_back({"deleted", erased, optional ? yes : no});
        auto doubled = lines;
        doubled.insert(doubled.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);
        variants.push_back(
            {"duplicated", doubled, comment ? yes : (keyword == "DATA" && encoding() == "binary" ? either : no)});
        variants.push_back({"garbage value", with(keyword + " abc"), if_comment});
        variants.push_back({"no value", with(keyword), if_comment});
        variants.push_back({"extra value", with(lines[i] + " 1"), if_comment});
        variants.push_back({"last value dropped", with(lines[i].substr(0, lines[i].rfind(' '))), if_comment});
        std::string lower = lines[i];
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        variants.push_back({"lowercase", with(lower), if_comment});
        variants.push_back({"keyword cut", with(lines[i].substr(1)), no});  // "# .PCD" loses its '#' too
        variants.push_back({"control byte", with(lines[i] + std::string(1, '\x01')), no});
        for (const auto& v : variants) {
            SCOPED_TRACE("line '" + lines[i] + "' " + v.name);
            const auto path = dir / ("line" + std::to_string(i) + ".pcd");
            write_bytes(path, join_lines(v.lines) + body());
            if (v.expect == yes) {
                EXPECT_EQ(outcome([&] { read_pcd(path); }), "ok");
            } else if (v.expect == no) {
                expect_error(path);
            } else {
                EXPECT_NE(outcome([&] { read_pcd(path); }), "other");
            }
            ++cases;
        }
    }
    EXPECT_GE(cases, 90);
}

TEST_P(PcdMalformed, TruncatedAtEveryOffset) {
    const PointCloud cloud = make_cloud(kW, kH, true);
    write_pcd(dir / "full.pcd", cloud, encoding_of(encoding()));
    const std::string full = read_bytes(dir / "full.pcd");
    // An ascii file cut inside its last line is still a valid file (with a shorter last number, or none missing).
    const std::size_t must_fail_below = encoding() == "ascii" ? full.rfind('\n', full.size() - 2) + 1 : full.size();
    for (std::size_t cut = 0; cut < full.size(); ++cut) {
        SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(full.size()));
        const auto path = dir / "cut.pcd";
        write_bytes(path, full.substr(0, cut));
        if (cut < must_fail_below) {
            expect_error(path);
        } else {
            EXPECT_NE(outcome([&] { read_pcd(path); }), "other");
        }
    }
}

TEST_P(PcdMalformed, RandomByteFlips) {
    const PointCloud cloud = make_cloud(kW, kH, true);
    write_pcd(dir / "full.pcd", cloud, encoding_of(encoding()));
    const std::string full = read_bytes(dir / "full.pcd");
    std::mt19937 rng(20240611u + static_cast<unsigned>(encoding().size()));
    int loaded = 0, failed = 0;
    for (int trial = 0; trial < 150; ++trial) {
        std::string bytes = full;
        const int flips = 1 + static_cast<int>(rng() % 4);
        for (int f = 0; f < flips; ++f) {
            // Half the flips hit the header, where the parsing logic is.
            const std::size_t header_len = full.find("DATA");
            const std::size_t pos = trial % 2 ? rng() % header_len : rng() % bytes.size();
            bytes[pos] = static_cast<char>(bytes[pos] ^ static_cast<char>(1 + rng() % 255));
        }
        if (trial % 10 == 9) bytes.insert(rng() % bytes.size(), 1, static_cast<char>(rng()));
        if (trial % 10 == 8) bytes.erase(rng() % bytes.size(), 1);
        const auto path = dir / "flip.pcd";
        write_bytes(path, bytes);
        const std::string r = outcome([&] { read_pcd(path); });
        ASSERT_NE(r, "other") << "trial " << trial;
        (r == "ok" ? loaded : failed)++;
    }
    EXPECT_GT(failed, 0);
    RecordProperty("loaded", loaded);
}

TEST_P(PcdMalformed, RandomDataAfterValidHeader) {
    std::mt19937 rng(77u);
    for (int trial = 0; trial < 60; ++trial) {
        std::string bytes = join_lines(header_lines());
        const std::size_t len = rng() % 700;
        for (std::size_t k = 0; k < len; ++k) bytes += static_cast<char>(rng());
        if (encoding() == "binary_compressed" && len >= 8) {
            // Make the sizes plausible so the LZF decoder itself gets the random data.
            const std::uint32_t c = static_cast<std::uint32_t>(len - 8), u = kW * kH * 16;
            std::memcpy(bytes.data() + bytes.size() - len, &c, 4);
            std::memcpy(bytes.data() + bytes.size() - len + 4, &u, 4);
        }
        write_bytes(dir / "rnd.pcd", bytes);
        ASSERT_NE(outcome([&] { read_pcd(dir / "rnd.pcd"); }), "other") << "trial " << trial;
    }
}

TEST_P(PcdMalformed, SizesLyingInBothDirections) {
    const auto lines = header_lines();
    auto set = [&](std::vector<std::pair<std::string, std::string>> edits) {
        auto l = lines;
        for (const auto& [key, value] : edits) {
            for (auto& line : l) {
                if (line.rfind(key + " ", 0) == 0) line = key + " " + value;
            }
        }
        return join_lines(l);
    };
    const auto path = dir / "lie.pcd";
    write_bytes(path, set({{"POINTS", "21"}}) + body());
    expect_error_containing(path, "POINTS 21 does not match WIDTH 5 x HEIGHT 4");
    write_bytes(path, set({{"POINTS", "19"}}) + body());
    expect_error_containing(path, "POINTS 19");
    // More points than the data holds.
    write_bytes(path, set({{"WIDTH", "6"}, {"POINTS", "24"}}) + body());
    expect_error(path);
    // Fewer: a binary file cannot tell (trailing bytes are allowed), the others can.
    write_bytes(path, set({{"WIDTH", "4"}, {"POINTS", "16"}}) + body());
    if (encoding() == "binary") {
        EXPECT_EQ(outcome([&] { read_pcd(path); }), "ok");
    } else {
        expect_error(path);
    }
    // Absurd sizes are refused before any allocation (ASan would report a multi-gigabyte request).
    write_bytes(path, set({{"WIDTH", "100000"}, {"HEIGHT", "100000"}, {"POINTS", "10000000000"}}) + body());
    expect_error_containing(path, "more points than pyrseg supports");
    write_bytes(path, set({{"WIDTH", "40000"}, {"HEIGHT", "40000"}, {"POINTS", "1600000000"}}) + body());
    expect_error(path);
    write_bytes(path, set({{"WIDTH", "18446744073709551617"}}) + body());
    expect_error_containing(path, "WIDTH '18446744073709551617' is not a non-negative integer");
    write_bytes(path, set({{"HEIGHT", "-4"}}) + body());
    expect_error_containing(path, "HEIGHT '-4'");
    write_bytes(path, set({{"COUNT", "1 1 1 4294967296"}}) + body());
    expect_error_containing(path, "field 'rgba': COUNT '4294967296'");
    write_bytes(path, set({{"COUNT", "1 1 1 0"}}) + body());
    expect_error_containing(path, "field 'rgba': COUNT '0'");
    write_bytes(path, set({{"COUNT", "1 1 1 2"}}) + body());  // points now larger than the data
    expect_error(path);
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PcdMalformed, ::testing::Values("ascii", "binary", "binary_compressed"));

// ---- binary_compressed block

class PcdCompressedBlock : public ::testing::Test {
protected:
    void SetUp() override {
        header_ = pcd_header(kXyzRgba, kW, kH, "binary_compressed");
        const std::string body = pcd_body(kXyzRgba, xyz_rgba_values(kW * kH), "binary_compressed");
        std::memcpy(&compressed_, body.data(), 4);
        std::memcpy(&uncompressed_, body.data() + 4, 4);
        block_ = body.substr(8);
        ASSERT_EQ(uncompressed_, kW * kH * 16u);
        ASSERT_EQ(compressed_, block_.size());
    }
    std::string file(std::uint32_t c, std::uint32_t u, const std::string& block) const {
        std::string s = header_;
        s.append(reinterpret_cast<const char*>(&c), 4);
        s.append(reinterpret_cast<const char*>(&u), 4);
        return s + block;
    }
    ScratchDir dir;
    std::string header_, block_;
    std::uint32_t compressed_ = 0, uncompressed_ = 0;
};

TEST_F(PcdCompressedBlock, CompressedSizeLies) {
    const auto path = dir / "c.pcd";
    write_bytes(path, file(compressed_ + 1, uncompressed_, block_));
    expect_error_containing(path, "compressed size " + std::to_string(compressed_ + 1) + " exceeds the " +
                                      std::to_string(compressed_) + " bytes left in the file");
    write_bytes(path, file(0xFFFFFFFFu, uncompressed_, block_));
    expect_error_containing(path, "exceeds");
    write_bytes(path, file(compressed_ / 2, uncompressed_, block_));
    expect_error_containing(path, "LZF");
    write_bytes(path, file(compressed_ - 1, uncompressed_, block_));
    expect_error_containing(path, "LZF");
    write_bytes(path, file(0, uncompressed_, block_));
    expect_error_containing(path, "compressed size 0");
    // Extra bytes past a correct block are padding, as in files from older PCL versions.
    write_bytes(path, file(compressed_, uncompressed_, block_ + std::string(100, '\x55')));
    EXPECT_EQ(outcome([&] { read_pcd(path); }), "ok");
}

TEST_F(PcdCompressedBlock, UncompressedSizeLies) {
    const auto path = dir / "u.pcd";
    for (const std::uint32_t u : {uncompressed_ - 4, uncompressed_ + 4, 0u, 0xFFFFFFFFu}) {
        write_bytes(path, file(compressed_, u, block_));
        expect_error_containing(path, "uncompressed size " + std::to_string(u) + " does not match the " +
                                          std::to_string(uncompressed_) + " bytes");
    }
}

TEST_F(PcdCompressedBlock, BadLzfData) {
    const auto path = dir / "l.pcd";
    // A back reference before the start of the output.
    write_bytes(path, file(compressed_, uncompressed_, std::string(block_.size(), '\xFF')));
    expect_error_containing(path, "corrupt LZF data");
    // A literal run longer than the block.
    write_bytes(path, file(5, uncompressed_,
                           std::string("\x1F"
                                       "abcd")));
    expect_error_containing(path, "LZF");
    // Valid LZF of the wrong length, both ways.
    const std::string raw(uncompressed_ - 16, 'a');
    const auto shorter = detail::lzf_pack(raw.data(), raw.size());
    const std::string s(shorter.begin(), shorter.end());
    write_bytes(path, file(static_cast<std::uint32_t>(s.size()), uncompressed_, s));
    expect_error_containing(path, "LZF data expands to " + std::to_string(raw.size()) + " bytes");
    const std::string more(uncompressed_ + 16, 'b');
    const auto longer = detail::lzf_pack(more.data(), more.size());
    const std::string l(longer.begin(), longer.end());
    write_bytes(path, file(static_cast<std::uint32_t>(l.size()), uncompressed_, l));
    expect_error_containing(path, "expands past the uncompressed size");
    // Ends before the two sizes.
    write_bytes(path, header_ + "\x10\x00\x00");
    expect_error_containing(path, "before the two block sizes");
}

TEST_F(PcdCompressedBlock, HugeClaimInTinyFileDoesNotAllocate) {
    // 200 million points of 16 bytes: 3.2 GB, still a valid 32-bit uncompressed size, in a file of a few hundred bytes.
    std::string h = header_;
    h.replace(h.find("WIDTH 5"), 7, "WIDTH 20000");
    h.replace(h.find("HEIGHT 4"), 8, "HEIGHT 10000");
    h.replace(h.find("POINTS 20"), 9, "POINTS 200000000");
    const std::uint32_t u = 3200000000u;
    std::string s = h;
    s.append(reinterpret_cast<const char*>(&compressed_), 4);
    s.append(reinterpret_cast<const char*>(&u), 4);
    write_bytes(dir / "huge.pcd", s + block_);
    expect_error_containing(dir / "huge.pcd", "too small to hold 3200000000 bytes");
}

// ---- header contents

struct HeaderCase {
    std::string fields, size, type, count, expected;
};

TEST(PcdUnsupported, FieldTypesAndCounts) {
    ScratchDir dir;
    const HeaderCase cases[] = {
        {"x y z rgba", "4 4 4 4", "F F F Q", "1 1 1 1", "field 'rgba': TYPE 'Q' is not F, I or U"},
        {"x y z rgba", "4 4 4 3", "F F F U", "1 1 1 1", "field 'rgba': SIZE '3' is not 1, 2, 4 or 8"},
        {"x y z h", "4 4 4 2", "F F F F", "1 1 1 1", "field 'h': TYPE F with SIZE 2 is not supported"},
        {"x y z", "4 4 4", "U F F", "1 1 1", "field 'x' must be TYPE F"},
        {"x y z", "4 4 2", "F F I", "1 1 1", "field 'z' must be TYPE F"},
        {"x y z", "4 4 4", "F F F", "1 2 1", "field 'y' must be TYPE F (SIZE 4 or 8) with COUNT 1"},
        {"x y z rgba", "4 4 4", "F F F U", "1 1 1 1", "SIZE has no entry for field 'rgba'"},
        {"x y z rgba", "4 4 4 4", "F F F U U", "1 1 1 1", "TYPE has 5 entries for 4 FIELDS"},
        {"x y z rgba", "4 4 4 4", "F F F U", "1 1 1", "COUNT has no entry for field 'rgba'"},
        {"x y z", "4 4 4", "F F FF", "1 1 1", "field 'z': TYPE 'FF'"},
        {"x y", "4 4", "F F", "1 1", "no field 'z'"},
        {"x y z x", "4 4 4 4", "F F F F", "1 1 1 1", "FIELDS lists field 'x' twice"},
        {"x y z normal_x", "4 4 4 4", "F F F F", "1 1 1 1", "missing normal_y normal_z"},
        {"x y z normal_x normal_y normal_z", "4 4 4 4 4 4", "F F F F F U", "1 1 1 1 1 1",
         "field 'normal_z' must be TYPE F"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.fields + " / " + c.size + " / " + c.type + " / " + c.count);
        write_bytes(dir / "t.pcd", "VERSION 0.7\nFIELDS " + c.fields + "\nSIZE " + c.size + "\nTYPE " + c.type +
                                       "\nCOUNT " + c.count + "\nWIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA binary\n" +
                                       std::string(4 * 64, '\0'));
        expect_error_containing(dir / "t.pcd", c.expected);
    }
}

TEST(PcdUnsupported, HeaderValues) {
    ScratchDir dir;
    const std::string fields = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
    const std::pair<std::string, std::string> cases[] = {
        {"VERSION 0.5\n" + fields + "WIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA ascii\n", "VERSION '0.5' is not supported"},
        {"VERSION 0.7\n" + fields + "WIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA zip\n", "DATA 'zip' is not ascii"},
        {"VERSION 0.7\n" + fields + "WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0\nPOINTS 4\nDATA ascii\n",
         "VIEWPOINT needs 7"},
        {"VERSION 0.7\n" + fields + "WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 nan 0 0 0\nPOINTS 4\nDATA ascii\n",
         "VIEWPOINT needs 7 finite"},
        {"VERSION 0.7\n" + fields + "WIDTH 2\nHEIGHT 2\nPOINTS 4\n", "header line 9 '1 2 3' is not a PCD header line"},
        {"VERSION 0.7\n" + fields + "HEIGHT 2\nPOINTS 4\nDATA ascii\n", "missing WIDTH line"},
        {"VERSION 0.7\n" + fields + "WIDTH 0\nHEIGHT 2\nPOINTS 0\nDATA ascii\n", "empty cloud"},
        {"VERSION 0.7\n" + fields + "WIDTH 2\nHEIGHT 2\nPOINTS 4\nCOLUMNS x y z\nDATA ascii\n",
         "header line 9 'COLUMNS x y z' is not a PCD header line"},
        {"VERSION 0.7\n\x1a\x02\x01\n",
         "header line 2 '?"
         "?"
         "?' is not text"},
        {"\x89PNG\r\n", "header line 1 '?PNG' is not a PCD header line"},
    };
    for (const auto& [text, expected] : cases) {
        write_bytes(dir / "h.pcd", text + "1 2 3\n4 5 6\n7 8 9\n1 2 3\n");
        expect_error_containing(dir / "h.pcd", expected);
    }
    write_bytes(dir / "empty.pcd", "");
    expect_error_containing(dir / "empty.pcd", "no DATA line");
    write_bytes(dir / "comments.pcd", "# only\n# comments\n");
    expect_error_containing(dir / "comments.pcd", "no DATA line");
}

TEST(PcdUnsupported, HugeCountInTinyFile) {
    ScratchDir dir;
    for (const auto& data : encodings()) {
        SCOPED_TRACE(data);
        // 2^24 values per point would make any per-value bookkeeping huge; the file's size must stop it first.
        write_bytes(dir / "c.pcd",
                    "VERSION 0.7\nFIELDS x y z hist\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 16777216\n"
                    "WIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA " +
                        data + "\n" + std::string(200, '1'));
        expect_error(dir / "c.pcd");
    }
}

TEST(PcdUnsupported, UnorganizedCloud) {
    ScratchDir dir;
    const PointCloud flat = make_cloud(20, 1, false);
    write_pcd(dir / "flat.pcd", flat, PcdEncoding::binary);  // a legal PCD file, just not one pyrseg can segment
    expect_error_containing(dir / "flat.pcd", "unorganized cloud (HEIGHT 1): pyrseg needs an organized cloud");
}

TEST(PcdUnsupported, AsciiGarbage) {
    ScratchDir dir;
    const std::string header =
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 2\nHEIGHT 2\n"
        "POINTS 4\nDATA ascii\n";
    const std::pair<std::string, std::string> cases[] = {
        {"1.0 2.0 3.0 4.0\n1 2 3 4\n1 2 3 4\n1 2 3\n", "data line 4 (point 3) has 3 values, the fields need 4"},
        {"1 2 3 4\n1 2 3 4 5\n1 2 3 4\n1 2 3 4\n", "(point 1) has more than the 4 values"},
        {"1.0 2.0 3.0 4.0\n1.0 2.0 3.0 4.0\n1.0 2.0 3.0 4.0\n", "the file ends after 3 of 4 points"},
        {"1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n", "more lines than the 4 points"},
        {"1 2 3 4\n1 2 3 4\n1 two 3 4\n1 2 3 4\n", "'two' in field 'y' is not a number"},
        {"1 2 3 4\n1 2 3 4\n1 2 3 red\n1 2 3 4\n", "'red' in field 'rgb' is not a number"},
        {"1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\x01\n", "is not a number"},
        {"1 2 3 4\n1 2 3 4\n1 2 3.5.5 4\n1 2 3 4\n", "'3.5.5'"},
        // A number float32 cannot hold is not "not a number": it says what is wrong with it.
        {"1 2 3 4\n1 2 3e50 4\n1 2 3 4\n1 2 3 4\n", "'3e50' in field 'z' is outside float32's range"},
        {"1 2 3 4\n1 -1e39 3 4\n1 2 3 4\n1 2 3 4\n", "'-1e39' in field 'y' is outside float32's range"},
        {"1 2 3 4 ", "cannot fit"},
        {"", "cannot fit"},
    };
    for (const auto& [body, expected] : cases) {
        write_bytes(dir / "g.pcd", header + body);
        expect_error_containing(dir / "g.pcd", expected);
    }
}

// A header longer than the reader reads is said to be that, not "no DATA line"; and a megabyte of FIELDS names is
// refused in linear time (a check against every earlier name took a minute for 1.2 MB).
TEST(PcdUnsupported, HeadersOfAMegabyte) {
    ScratchDir dir;
    std::string fields = "FIELDS x y z";
    for (int i = 0; fields.size() < (std::size_t{12} << 17); ++i) fields += " f" + std::to_string(i);
    write_bytes(dir / "long.pcd", "VERSION 0.7\n" + fields +
                                      "\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
                                      "DATA ascii\n1 2 3\n");
    const auto start = std::chrono::steady_clock::now();
    expect_error_containing(dir / "long.pcd", "the header is longer than pyrseg reads");
    std::string names = "VERSION 0.7\nFIELDS x y z";
    for (int i = 0; names.size() < (std::size_t{1} << 20) - 4096; ++i) names += " f" + std::to_string(i);
    write_bytes(dir / "names.pcd",
                names + "\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
    expect_error_containing(dir / "names.pcd", "SIZE has no entry for field 'f0'");
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    EXPECT_LT(took.count(), 5.0) << "a 1.5 MB and a 1 MB header took " << took.count() << " s to refuse";
}

TEST(PcdUnsupported, NotAFile) {
    ScratchDir dir;
    std::string message;
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { read_pcd(dir / "nonexistent.pcd"); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
    EXPECT_NE(message.find("nonexistent.pcd: cannot open"), std::string::npos) << message;

    fs::create_directories(dir / "folder.pcd");
    EXPECT_EQ(outcome([&] { read_pcd(dir / "folder.pcd"); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
    EXPECT_NE(message.find("folder.pcd: cannot read: is a directory"), std::string::npos) << message;
}

}  // namespace
}  // namespace pyrseg::io::test
