#pragma once
// What a Segmenter holds; for core/segmenter.cpp and core/device_frame.cpp.
#include <memory>
#include <string>
#include <vector>

#include "core/depth_camera.hpp"
#include "core/depth_tables.hpp"
#include "core/executor.hpp"
#include "core/plan.hpp"
#include "core/segment_tracks.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg {

struct Segmenter::Impl {
    core::Plan plan;
    std::string backend;
    Outputs outputs;
    std::unique_ptr<core::PassExecutor> executor;
    std::vector<PassTiming> timings;
    core::DepthTables depth_tables;           // a depth frame's constants, reused
    core::CheckedDepthCamera checked_camera;  // the camera whose frame check_depth_camera last passed
    core::TrackState tracks;                  // Outputs::segment_tracks: the stream's tracks
};

namespace core {
struct SegmenterAccess {
    // Throws pyrseg::Error for a moved-from Segmenter.
    static Segmenter::Impl& impl(Segmenter& segmenter);
};
}  // namespace core

}  // namespace pyrseg
