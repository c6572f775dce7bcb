// read_png (libpng): every colour type and bit depth it converts to 8- or 16-bit samples.
#include <cstddef>
#include <cstdint>

#include "pyrseg/io.hpp"
#include "tests/fuzz/fuzz_input.hpp"
#include "tests/fuzz/image_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = pyrseg::fuzz::write_input(data, size, ".png");
    pyrseg::fuzz::tolerate_format_errors([&] { pyrseg::fuzz::check_image(pyrseg::io::read_png(path)); });
    return 0;
}
