#pragma once
// Which files a batch (pyrseg segment INPUT... --out-dir DIR) writes, planned before any frame is read: every
// output name is distinct from every input of the batch and from every other output (issue 32: a.npy's labels
// a.labels.npy once replaced the batch's next input, and a.pcd's mask and a.mask.pcd's picture were one file).
// Pure naming (it only asks the file system which names are one file), so that a fuzz harness can call it.
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace pyrseg::cli {

struct PlannedFrame {
    std::filesystem::path input;
    std::map<std::string, std::filesystem::path> outputs;  // by kind, as --write names them: labels, png, ...
};

// The kinds --write accepts, and the name each writes for a frame named NAME.
[[nodiscard]] const std::map<std::string, std::string>& batch_output_suffixes();

// DIR/NAME.labels.npy, NAME.png, NAME.mask.png, NAME.figure.png, NAME.ply, NAME.labels.pcd, NAME.stats.json,
// NAME.graph.json, NAME.scene.json, NAME.track_ids.npy, NAME.tracks.json for the `kinds` asked, NAME being the input's
// stem, or NAME_2, NAME_3, ... when one of those names is already another frame's. An output that would be one of the
// inputs is a UsageError naming both (nothing is read or written then).
[[nodiscard]] std::vector<PlannedFrame> plan_batch(const std::vector<std::filesystem::path>& inputs,
                                                   const std::filesystem::path& out_dir,
                                                   const std::set<std::string>& kinds);

}  // namespace pyrseg::cli
