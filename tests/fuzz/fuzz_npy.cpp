// read_npy and read_npy_cloud on the same file: the generic array reader and the cloud view of it.
#include <cstddef>
#include <cstdint>

#include "pyrseg/io.hpp"
#include "tests/fuzz/cloud_checks.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = pyrseg::fuzz::write_input(data, size, ".npy");
    pyrseg::fuzz::tolerate_format_errors([&] {
        const pyrseg::io::NpyArray array = pyrseg::io::read_npy(path);
        // The data can only be as long as the file it came from.
        pyrseg::fuzz::expect(array.bytes.size() <= size);
    });
    pyrseg::fuzz::tolerate_format_errors([&] { pyrseg::fuzz::check_cloud(pyrseg::io::read_npy_cloud(path)); });
    return 0;
}
