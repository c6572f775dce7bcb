// The depth image path of `pyrseg segment`: read_depth_image (PNG or TIFF, as the file's magic says: the reader
// goes by the extension) and depth_to_cloud on what it returns.
#include <algorithm>
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
        // A camera that fits whatever size the file has (about 53 degrees across), so that the back-projection runs
        // rather than the camera check refusing the principal point.
        const double f = double(std::max(image.width, image.height));
        const pyrseg::io::Intrinsics k{f, f, image.width / 2.0, image.height / 2.0};
        pyrseg::fuzz::check_cloud(pyrseg::io::depth_to_cloud(image, k, image.floating ? 1.0 : 0.001));
    });
    return 0;
}
