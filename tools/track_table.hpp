#pragma once
// A frame's tracks (Result::tracks, docs/algorithm.md section 11) as `pyrseg segment --tracks` writes them: CSV with
// a header line when the path ends in .csv, else JSON with the frame's size, source and place in the stream, as
// io::write_segment_stats and io::write_segment_graph write theirs.
#include <cstdint>
#include <string>
#include <vector>

#include "pyrseg/io.hpp"
#include "pyrseg/result.hpp"

namespace pyrseg::cli {

// "new_track", "overlap", "position": the names pyrseg.TrackMatch gives them in Python.
[[nodiscard]] const char* track_match_name(TrackMatch how);

// The file's text; `stream_frame` is the frame's number in its stream (0 for the first: first_frame counts the same).
[[nodiscard]] std::string segment_tracks_text(const std::vector<SegmentTrack>& tracks, const io::SegmentTable& frame,
                                              std::uint32_t stream_frame, bool csv);

}  // namespace pyrseg::cli
