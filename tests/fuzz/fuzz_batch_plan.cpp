// The CLI's batch planner (tools/batch_plan.hpp): a list of input names (folders, duplicates, one stem in several
// folders, names like a.labels.npy or NAME.png, some of them existing files, some links), an output folder and the
// --write kinds, decoded from the input. Its promises, checked for every plan it gives: every output is distinct
// from every input and from every other output (as the file system sees names: same_file_key), and lies directly
// in the output folder. A refused plan is the CLI's UsageError or a pyrseg::Error; anything else is a finding.
// Every name lies in the harness's own scratch folder (/dev/shm/pyrseg-fuzz-PID/batch), where the files it makes
// live: the planner itself writes nothing.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "pyrseg/error.hpp"
#include "tests/fuzz/fuzz_input.hpp"
#include "tools/args.hpp"
#include "tools/batch_plan.hpp"
#include "tools/output_checks.hpp"

namespace fs = std::filesystem;
using pyrseg::fuzz::expect;

namespace {

// Path pieces the names are made of: folders (one of them a link to another), dots, stems and the suffixes the
// outputs have.
const char* const kPieces[] = {"a",    "b",           "scan",        ".",           "..",        "d",           "e",
                               "link", ".npy",        ".png",        ".labels.npy", ".mask.png", ".figure.png", ".ply",
                               ".pcd", ".labels.pcd", ".stats.json", "_2",          " ",         "\x01",        "\xff"};
constexpr int kPieceCount = int(sizeof kPieces / sizeof kPieces[0]);
const char* const kKinds[] = {"labels", "png", "mask", "figure", "ply", "pcd", "stats", "x"};

std::string name(FuzzedDataProvider& in) {
    std::string s;
    const int parts = in.ConsumeIntegralInRange<int>(1, 5);
    for (int i = 0; i < parts; ++i) {
        if (i > 0 && in.ConsumeBool()) s += "/";
        s += kPieces[in.ConsumeIntegralInRange<int>(0, kPieceCount - 1)];
    }
    return s;
}

const fs::path& root() {
    static const fs::path r = [] {
        static const pyrseg::fuzz::ScratchFolder folder;
        return folder.path() / "batch";
    }();
    return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    std::error_code ec;
    fs::remove_all(root(), ec);
    fs::create_directories(root() / "a", ec);
    fs::create_directories(root() / "b", ec);
    fs::create_symlink("a", root() / "link", ec);
    std::vector<fs::path> inputs;
    const int n = in.ConsumeIntegralInRange<int>(1, 8);
    for (int i = 0; i < n; ++i) {
        const fs::path p = root() / name(in);
        inputs.push_back(p);
        // Some inputs exist (the planner then compares inodes), some do not (it compares resolved paths).
        if (in.ConsumeBool()) {
            fs::create_directories(p.parent_path(), ec);
            std::FILE* f = std::fopen(p.c_str(), "ab");
            if (f != nullptr) std::fclose(f);
        }
    }
    const fs::path out_dir = root() / (in.ConsumeBool() ? std::string("out") : name(in));
    fs::create_directories(out_dir, ec);
    std::set<std::string> kinds;
    const int k = in.ConsumeIntegralInRange<int>(0, 8);
    for (int i = 0; i < k; ++i) kinds.insert(kKinds[in.ConsumeIntegralInRange<int>(0, 7)]);
    try {
        const std::vector<pyrseg::cli::PlannedFrame> plan = pyrseg::cli::plan_batch(inputs, out_dir, kinds);
        expect(plan.size() == inputs.size());
        std::set<std::string> input_keys, output_keys;
        for (const fs::path& p : inputs) input_keys.insert(pyrseg::cli::same_file_key(p));
        for (std::size_t i = 0; i < plan.size(); ++i) {
            expect(plan[i].input == inputs[i]);
            for (const auto& [kind, path] : plan[i].outputs) {
                expect(kinds.count(kind) != 0);
                // Directly in the output folder: a plain file name, no separator, no . or ..
                expect(path.parent_path() == out_dir);
                const std::string file = path.filename().string();
                expect(!file.empty() && file != "." && file != ".." && file.find('/') == std::string::npos);
                const std::string key = pyrseg::cli::same_file_key(path);
                expect(input_keys.count(key) == 0);
                expect(output_keys.insert(key).second);
            }
        }
    } catch (const pyrseg::cli::UsageError&) {
    } catch (const pyrseg::Error&) {
    }
    return 0;
}
