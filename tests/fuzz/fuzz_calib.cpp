// read_intrinsics: calibration files in OpenCV's FileStorage layout (XML, YAML, JSON), at the top level and at the
// named nodes the seeds use.
#include <cstddef>
#include <cstdint>

#include "pyrseg/io.hpp"
#include "tests/fuzz/fuzz_input.hpp"

namespace {

// The extension the content suggests, as a real calibration file would have: a reader that goes by the extension
// (OpenCV's FileStorage did) then keeps each seed in the parser it was written for.
const char* extension_for(const std::uint8_t* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) {
        if (data[i] == ' ' || data[i] == '\n' || data[i] == '\r' || data[i] == '\t') continue;
        if (data[i] == '<') return ".xml";
        if (data[i] == '{') return ".json";
        break;
    }
    return ".yml";
}

void check(const pyrseg::io::Intrinsics& k) {
    pyrseg::fuzz::expect(k.fx > 0 && k.fy > 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = pyrseg::fuzz::write_input(data, size, extension_for(data, size));
    pyrseg::fuzz::tolerate_format_errors([&] { check(pyrseg::io::read_intrinsics(path)); });
    for (const char* node : {"camera_matrix", "IR_intrinsic_params"}) {
        pyrseg::fuzz::tolerate_format_errors([&] { check(pyrseg::io::read_intrinsics(path, node)); });
    }
    return 0;
}
