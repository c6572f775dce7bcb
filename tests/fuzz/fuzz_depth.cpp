// The depth image path of `pyrseg segment`: read_depth_image (PNG or TIFF, as the file's magic says: the reader
// goes by the extension) and depth_to_cloud on what it returns.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "pyrseg/io.hpp"
#include "tests/fuzz/cloud_checks.hpp"
#include "tests/fuzz/fuzz_input.hpp"
#include "tests/fuzz/image_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool png = size >= 4 && std::memcmp(data, "\x89PNG", 4) == 0;
    const auto path = pyrseg::fuzz::write_input(data, size, png ? ".png" : ".tiff");
    pyrseg::fuzz::tolerate_format_errors([&] {
        const pyrseg::io::DepthImage image = pyrseg::io::read_depth_image(path);
        pyrseg::fuzz::check_depth(image);
        const pyrseg::io::Intrinsics k{525.0, 525.0, 319.5, 239.5};
        pyrseg::fuzz::check_cloud(pyrseg::io::depth_to_cloud(image, k, image.floating ? 1000.0 : 1.0));
    });
    return 0;
}
