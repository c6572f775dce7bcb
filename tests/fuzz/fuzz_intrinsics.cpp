// parse_intrinsics: the --intrinsics "fx,fy,cx,cy" text.
#include <cstddef>
#include <cstdint>
#include <string>

#include "pyrseg/io.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    pyrseg::fuzz::tolerate_format_errors([&] {
        const pyrseg::io::Intrinsics k = pyrseg::io::parse_intrinsics(text);
        pyrseg::fuzz::expect(k.fx > 0 && k.fy > 0);
    });
    return 0;
}
