#include "tools/eval_sensors.hpp"

#include <algorithm>
#include <optional>
#include <sstream>

#include "pyrseg/error.hpp"
#include "tools/args.hpp"
#include "tools/printable.hpp"

namespace pyrseg::cli {

std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) items.push_back(item);
    return items;
}

std::string known_sensors(const char* separator) {
    std::string known;
    for (const SensorKind kind : sensor_kinds()) {
        known += std::string(known.empty() ? "" : separator) + sensor_kind_name(kind);
    }
    return known;
}

std::vector<synthetic::Sensor> parse_sensors(const std::string& text) {
    std::vector<synthetic::Sensor> sensors;
    for (std::string item : split_list(text)) {
        item.erase(0, std::min(item.size(), item.find_first_not_of(' ')));
        item.erase(item.find_last_not_of(' ') + 1);
        const std::optional<synthetic::Sensor> sensor = synthetic::sensor_from_name(item);
        if (!sensor) {
            throw UsageError{"--sensors: unknown sensor model '" + printable(item) + "'; known: " + known_sensors()};
        }
        if (std::find(sensors.begin(), sensors.end(), *sensor) == sensors.end()) sensors.push_back(*sensor);
    }
    if (sensors.empty()) throw UsageError{"--sensors is empty; known: " + known_sensors()};
    return sensors;
}

SensorKind kind_of(synthetic::Sensor sensor) {
    const char* name = synthetic::sensor_name(sensor);
    const std::optional<SensorKind> kind = name != nullptr ? sensor_kind_from_name(name) : std::nullopt;
    if (!kind) throw Error(ErrorCode::internal, "eval: no preset for the sensor model");
    return *kind;
}

}  // namespace pyrseg::cli
