// The table of temporary files a termination signal's handler empties (io/temporary_files.hpp): what is registered
// is removed, what was unregistered (its output renamed into place) is not, and a registration moves with its owner.
#include <gtest/gtest.h>

#include <fstream>
#include <utility>
#include <vector>

#include "io/temporary_files.hpp"
#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

void touch(const fs::path& path) {
    std::ofstream(path) << "x";
}

TEST(TemporaryFiles, RegisteredOnesAreRemovedAndNoOthers) {
    const ScratchDir dir;
    touch(dir / "kept");
    touch(dir / "registered");
    touch(dir / "moved");
    touch(dir / "done");
    { const detail::RegisteredTemporary done(dir / "done"); }  // unregistered: its output went into place
    const detail::RegisteredTemporary registered(dir / "registered");
    detail::RegisteredTemporary first(dir / "moved");
    const detail::RegisteredTemporary second = std::move(first);
    detail::remove_registered_temporaries();
    EXPECT_EQ(files_in(dir.path()), (std::vector<fs::path>{"done", "kept"}));
}

TEST(TemporaryFiles, MoreThanTheTableHoldsAreNotRegistered) {
    const ScratchDir dir;
    std::vector<detail::RegisteredTemporary> many;
    for (int i = 0; i < 80; ++i) {
        touch(dir / std::to_string(i));
        many.emplace_back(dir / std::to_string(i));
    }
    detail::remove_registered_temporaries();
    EXPECT_EQ(files_in(dir.path()).size(), 80u - 64u);  // the first 64 registered, the others left as they were
}

}  // namespace
}  // namespace pyrseg::io::test
