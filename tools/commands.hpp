#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pyrseg/depth.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/presets.hpp"
#include "tools/args.hpp"

namespace pyrseg::cli {

// Each command returns the process exit status: 0 success, 1 failure, 2 usage error.
int cmd_segment(const std::vector<std::string>& args);
int cmd_backends(const std::vector<std::string>& args);
int cmd_demo(const std::vector<std::string>& args);
int cmd_eval(const std::vector<std::string>& args);
// `pyrseg eval --tabletop DIR` (cmd_eval_tabletop.cpp), which cmd_eval hands over to.
int cmd_eval_tabletop(const std::vector<std::string>& args);
// `pyrseg eval --tracks` (cmd_eval_tracks.cpp): track ids over synthetic sequences, which cmd_eval hands over to.
int cmd_eval_tracks(const std::vector<std::string>& args);
int cmd_bench_report(const std::vector<std::string>& args);

// Parameters shared by the commands that segment: --ct --dt --unit-mm --bridge-levels --unjoinable-gap
// --normal-radius --no-label-edges --raw.
extern const char* const kParameterHelp;
extern const std::set<std::string> kParameterValueOptions;
extern const std::set<std::string> kParameterFlagOptions;
// The tracks' parameters, --track-max-distance and --track-hold: segment's alone (parse_params reads them when given).
extern const char* const kTrackParameterHelp;
extern const std::set<std::string> kTrackValueOptions;
// --sensor: a preset, or auto (chosen per frame by measure_frame_noise).
struct SensorChoice {
    bool automatic = false;
    SensorKind kind = SensorKind::structured_light;
};
[[nodiscard]] std::optional<SensorChoice> parse_sensor(const Args& args);
// The parameters: the preset (given, else --sensor's unless auto, else the defaults), then the explicit options.
[[nodiscard]] Params parse_params(const Args& args, std::optional<SensorKind> preset = std::nullopt);

// The inputs `segment` reads: organized PCD, or a depth image with intrinsics (--intrinsics, --calib,
// --metres-per-unit), turned into a cloud in millimetres.
extern const char* const kInputHelp;
extern const std::set<std::string> kInputValueOptions;
// Once per run, before any input is read: refuses contradicting input options and warns about deprecated ones.
void check_input_options(const Args& args);
// A depth image's samples as the file holds them, for Segmenter::segment(DepthView): back-projected on the device.
struct DepthFrame {
    std::vector<std::uint16_t> u16;  // one of the two, W*H
    std::vector<float> f32;
    double metres_per_unit = 0.001;
    io::Intrinsics intrinsics;
    [[nodiscard]] DepthView view(int width, int height) const;
};

struct LoadedInput {
    io::PointCloud cloud;  // the points (for depth images, back-projected on the host: outputs that need a cloud)
    std::string kind;      // "PCD", "depth image"
    bool millimetres;      // the cloud is in millimetres whatever --unit-mm says
    std::optional<DepthFrame> depth;       // depth images and NumPy depth maps: segmented from these samples
    std::vector<std::uint8_t> color = {};  // --color's image, RGB8, W*H*3 (empty without --color)
};
[[nodiscard]] LoadedInput load_input(const std::filesystem::path& path, const Args& args);
// Whether load_input reads files with this path's extension (batches pick such files out of folders).
[[nodiscard]] bool is_supported_input(const std::filesystem::path& path);

}  // namespace pyrseg::cli
