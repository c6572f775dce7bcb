// The batch planner (tools/batch_plan.hpp) called directly: every output name distinct from every input and from
// every other output, or a UsageError before anything is read.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "tools/args.hpp"
#include "tools/batch_plan.hpp"
#include "tools/output_checks.hpp"

namespace {

namespace fs = std::filesystem;
using pyrseg::cli::plan_batch;
using pyrseg::cli::PlannedFrame;

class BatchPlan : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pyrseg_batch_plan_test_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "a");
        fs::create_directories(dir_ / "b");
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    fs::path touch(const fs::path& relative) const {
        const fs::path path = dir_ / relative;
        std::ofstream(path) << "x";
        return path;
    }
    fs::path dir_;
};

// Every output key of the plan, checked distinct and apart from the inputs'.
void expect_distinct(const std::vector<fs::path>& inputs, const std::vector<PlannedFrame>& plan) {
    std::set<std::string> keys;
    for (const fs::path& input : inputs) keys.insert(pyrseg::cli::same_file_key(input));
    const std::size_t input_count = keys.size();
    std::size_t outputs = 0;
    for (const PlannedFrame& frame : plan) {
        for (const auto& [kind, path] : frame.outputs) {
            ++outputs;
            EXPECT_TRUE(keys.insert(pyrseg::cli::same_file_key(path)).second) << kind << " " << path;
        }
    }
    EXPECT_EQ(keys.size(), input_count + outputs);
}

TEST_F(BatchPlan, InputsSharingANameInDifferentFoldersGetDistinctNames) {
    const std::vector<fs::path> inputs = {touch("a/x.pcd"), touch("b/x.pcd")};
    const auto plan = plan_batch(inputs, dir_ / "out", {"labels", "png"});
    ASSERT_EQ(plan.size(), 2u);
    EXPECT_EQ(plan[0].outputs.at("png"), dir_ / "out" / "x.png");
    EXPECT_EQ(plan[1].outputs.at("png"), dir_ / "out" / "x_2.png");
    expect_distinct(inputs, plan);
}

TEST_F(BatchPlan, OneFramesOutputIsNeverAnothersOfAnotherKind) {
    const std::vector<fs::path> inputs = {touch("a/s.pcd"), touch("a/s.mask.pcd"), touch("a/s.figure.ply")};
    const auto plan = plan_batch(inputs, dir_ / "out", {"png", "mask", "figure", "ply"});
    expect_distinct(inputs, plan);
}

TEST_F(BatchPlan, AnOutputThatIsAnInputIsAUsageError) {
    const std::vector<fs::path> inputs = {touch("a/f.npy"), touch("a/f.labels.npy")};
    EXPECT_THROW((void)plan_batch(inputs, dir_ / "a", {"labels"}), pyrseg::cli::UsageError);
    // Spelt differently, or through a symbolic link to the folder: the same file.
    fs::create_directory_symlink(dir_ / "a", dir_ / "link");
    EXPECT_THROW((void)plan_batch(inputs, dir_ / "link" / ".", {"labels"}), pyrseg::cli::UsageError);
    // Elsewhere: fine.
    expect_distinct(inputs, plan_batch(inputs, dir_ / "b", {"labels", "png"}));
    // A depth image NAME.png of the batch is another cloud's colour picture.
    const std::vector<fs::path> mixed = {touch("a/d.pcd"), touch("a/d.png")};
    EXPECT_THROW((void)plan_batch(mixed, dir_ / "a", {"png"}), pyrseg::cli::UsageError);
}

}  // namespace
