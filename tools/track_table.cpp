#include "tools/track_table.hpp"

#include <nlohmann/json.hpp>

namespace pyrseg::cli {

const char* track_match_name(TrackMatch how) {
    switch (how) {
        case TrackMatch::new_track:
            return "new_track";
        case TrackMatch::overlap:
            return "overlap";
        case TrackMatch::position:
            return "position";
    }
    return "unknown";
}

std::string segment_tracks_text(const std::vector<SegmentTrack>& tracks, const io::SegmentTable& frame,
                                std::uint32_t stream_frame, bool csv) {
    if (csv) {
        std::string out = "label,id,first_frame,age,hidden_frames,how\n";
        for (const SegmentTrack& t : tracks) {
            out += std::to_string(t.label) + ',' + std::to_string(t.id) + ',' + std::to_string(t.first_frame) + ',' +
                   std::to_string(t.age) + ',' + std::to_string(t.hidden_frames) + ',' + track_match_name(t.how) + '\n';
        }
        return out;
    }
    nlohmann::json doc;
    doc["source"] = frame.source;
    doc["width"] = frame.width;
    doc["height"] = frame.height;
    doc["stream_frame"] = stream_frame;
    doc["track_count"] = tracks.size();
    nlohmann::json list = nlohmann::json::array();
    for (const SegmentTrack& t : tracks) {
        list.push_back({{"label", t.label},
                        {"id", t.id},
                        {"first_frame", t.first_frame},
                        {"age", t.age},
                        {"hidden_frames", t.hidden_frames},
                        {"how", track_match_name(t.how)}});
    }
    doc["tracks"] = std::move(list);
    return doc.dump(1) + "\n";
}

}  // namespace pyrseg::cli
