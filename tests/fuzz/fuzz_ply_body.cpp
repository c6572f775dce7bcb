// read_ply with a valid header (tests/fuzz/ply_headers.hpp, chosen by the first byte) and the rest of the input as
// the body: the data PCL parses once pyrseg's header check has let the file through.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pyrseg/io.hpp"
#include "tests/fuzz/cloud_checks.hpp"
#include "tests/fuzz/fuzz_input.hpp"
#include "tests/fuzz/ply_headers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const auto& header = pyrseg::fuzz::kPlyHeaders[data[0] % pyrseg::fuzz::kPlyHeaders.size()].text;
    std::vector<std::uint8_t> file(header.begin(), header.end());
    file.insert(file.end(), data + 1, data + size);
    const auto path = pyrseg::fuzz::write_input(file.data(), file.size(), ".ply");
    pyrseg::fuzz::tolerate_format_errors([&] { pyrseg::fuzz::check_cloud(pyrseg::io::read_ply(path)); });
    return 0;
}
