// read_ply on whole files: pyrseg's strict header check, then PCL's PLY reader.
#include <cstddef>
#include <cstdint>

#include "pyrseg/io.hpp"
#include "tests/fuzz/cloud_checks.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = pyrseg::fuzz::write_input(data, size, ".ply");
    pyrseg::fuzz::tolerate_format_errors([&] { pyrseg::fuzz::check_cloud(pyrseg::io::read_ply(path)); });
    return 0;
}
