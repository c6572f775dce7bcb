#pragma once
// The SPIR-V of every entry point of shaders/pyr_vulkan.comp, compiled and checked at build time
// (backends/CMakeLists.txt generates the table).
#include <cstddef>
#include <cstdint>

namespace pyrseg::vulkan {

struct SpirvModule {
    const char* entry;  // NAME of PYR_ENTRY_<NAME>
    const std::uint32_t* words;
    std::size_t word_count;
};

extern const SpirvModule kSpirvModules[];
extern const std::size_t kSpirvModuleCount;

}  // namespace pyrseg::vulkan
