// Helpers shared by the stage files.
#include "stages/stage_util.h"

#include <fmt/format.h>

namespace mill {

nlohmann::json case_keys(const config::Document& doc, const std::vector<std::string>& prefixes) {
  nlohmann::json all = doc.to_json(), out = nlohmann::json::object();
  for (auto it = all.begin(); it != all.end(); ++it)
    for (const auto& p : prefixes)
      if (it.key().compare(0, p.size(), p) == 0) out[it.key()] = it.value();
  return out;
}

nlohmann::json ore_keys(const config::Document& ore) {
  nlohmann::json all = ore.to_json(), out = nlohmann::json::object();
  for (auto it = all.begin(); it != all.end(); ++it)
    if (it.key() != "name" && it.key() != "source" && it.key().rfind("calibrated.", 0) != 0 &&
        it.key().rfind("jk.", 0) != 0) out[it.key()] = it.value();
  return out;
}

std::string rpm_label(double rpm) { return fmt::format("rpm{:g}", rpm); }

std::string impact_label(double velocity, double angle, int repeat) {
  return fmt::format("v{:g}_a{:g}_r{}", velocity, angle, repeat);
}

}  // namespace mill
