#pragma once
// The evaluations' shared options: comma-separated lists, and the synthetic sensor models named by --sensors with
// the preset each is evaluated with (pyrseg eval and pyrseg eval --tracks).
#include <string>
#include <vector>

#include "pyrseg/presets.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::cli {

// "a,b,c" -> {"a", "b", "c"}, empty items kept.
[[nodiscard]] std::vector<std::string> split_list(const std::string& text);
// "structured-light, kinect-v1, ..." (separator ", "), or as a --sensors list (",").
[[nodiscard]] std::string known_sensors(const char* separator = ", ");
// The sensor models named (spaces around a name ignored), in the order given, each once; a UsageError naming an
// unknown one, or an empty list.
[[nodiscard]] std::vector<synthetic::Sensor> parse_sensors(const std::string& text);
// The preset of a sensor model.
[[nodiscard]] SensorKind kind_of(synthetic::Sensor sensor);

}  // namespace pyrseg::cli
