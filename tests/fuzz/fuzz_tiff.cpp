// read_depth_image on TIFF files (libtiff): 16-bit unsigned and 32-bit float samples, strips or tiles.
#include <cstddef>
#include <cstdint>

#include "pyrseg/io.hpp"
#include "tests/fuzz/fuzz_input.hpp"
#include "tests/fuzz/image_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = pyrseg::fuzz::write_input(data, size, ".tif");
    pyrseg::fuzz::tolerate_format_errors([&] { pyrseg::fuzz::check_depth(pyrseg::io::read_depth_image(path)); });
    return 0;
}
