#include "tools/batch_plan.hpp"

#include "tools/args.hpp"
#include "tools/output_checks.hpp"
#include "tools/printable.hpp"

namespace pyrseg::cli {

namespace fs = std::filesystem;

const std::map<std::string, std::string>& batch_output_suffixes() {
    static const std::map<std::string, std::string> suffixes = {
        {"labels", ".labels.npy"},
        {"png", ".png"},
        {"mask", ".mask.png"},
        {"figure", ".figure.png"},
        {"ply", ".ply"},
        {"pcd", ".labels.pcd"},
        {"stats", ".stats.json"},
        {"graph", ".graph.json"},
        {"scene", ".scene.json"},
        {"track_ids", ".track_ids.npy"},
        {"tracks", ".tracks.json"},
    };
    return suffixes;
}

std::vector<PlannedFrame> plan_batch(const std::vector<fs::path>& inputs, const fs::path& out_dir,
                                     const std::set<std::string>& kinds) {
    std::map<std::string, fs::path> input_keys;  // same_file_key -> the input
    for (const fs::path& input : inputs) input_keys.emplace(same_file_key(input), input);
    std::set<std::string> planned;  // the outputs' keys so far
    std::vector<PlannedFrame> plan;
    plan.reserve(inputs.size());
    for (const fs::path& input : inputs) {
        PlannedFrame frame{input, {}};
        std::map<std::string, std::string> keys;  // kind -> key
        const std::string stem = input.stem().string();
        for (int n = 1;; ++n) {
            const std::string name = n == 1 ? stem : stem + "_" + std::to_string(n);
            frame.outputs.clear();
            keys.clear();
            bool taken = false;
            for (const std::string& kind : kinds) {
                const auto suffix = batch_output_suffixes().find(kind);
                if (suffix == batch_output_suffixes().end()) continue;
                const fs::path path = out_dir / (name + suffix->second);
                const std::string key = same_file_key(path);
                taken = taken || planned.count(key) != 0;
                frame.outputs.emplace(kind, path);
                keys.emplace(kind, key);
            }
            // Two of one frame's own names cannot meet: the suffixes differ.
            if (!taken) break;
        }
        for (const auto& [kind, key] : keys) {
            const auto input_hit = input_keys.find(key);
            if (input_hit != input_keys.end()) {
                std::string message = "the " + kind + " output of " + printable(input) + " would be ";
                message += printable(frame.outputs.at(kind));
                message += ", which is an input of the batch";
                if (input_hit->second != frame.outputs.at(kind)) message += " (" + printable(input_hit->second) + ")";
                message += ": refusing to overwrite it; give another --out-dir, or leave " + kind + " out of --write";
                throw UsageError{message};
            }
            planned.insert(key);
        }
        plan.push_back(std::move(frame));
    }
    return plan;
}

}  // namespace pyrseg::cli
