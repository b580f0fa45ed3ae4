// Output file checks for "a job is done only if its outputs exist and parse".
#include "jobs/output_checks.h"

#include <fmt/format.h>
#include <hdf5.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace mill::jobs {
namespace fs = std::filesystem;

std::string check_file(const fs::path& f) {
  std::error_code ec;
  if (!fs::exists(f, ec)) return f.string() + ": missing";
  if (!fs::is_regular_file(f, ec)) return f.string() + ": not a regular file";
  if (fs::file_size(f, ec) == 0) return f.string() + ": empty";
  return "";
}

std::string check_exists(const fs::path& f) {
  std::error_code ec;
  if (!fs::exists(f, ec)) return f.string() + ": missing";
  if (!fs::is_regular_file(f, ec)) return f.string() + ": not a regular file";
  return "";
}

namespace {
std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

std::string check_json(const fs::path& f, bool array_ok) {
  if (auto r = check_file(f); !r.empty()) return r;
  try {
    const auto j = nlohmann::json::parse(slurp(f));
    if (j.is_object() || (array_ok && j.is_array())) return "";
    return f.string() + ": expected a JSON " + (array_ok ? "object or array" : "object") + ", got " + j.type_name();
  } catch (const nlohmann::json::exception& e) {
    return fmt::format("{}: not valid JSON ({})", f.string(), e.what());
  }
}

std::string check_hdf5(const fs::path& f) {
  if (auto r = check_file(f); !r.empty()) return r;
  // Silence the library's own error stack print while probing.
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  H5Eget_auto2(H5E_DEFAULT, &func, &data);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t id = H5Fopen(f.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id >= 0) H5Fclose(id);
  H5Eset_auto2(H5E_DEFAULT, func, data);
  return id >= 0 ? "" : f.string() + ": not a readable HDF5 file (truncated or overwritten?)";
}

std::string check_yaml_map(const fs::path& f) {
  if (auto r = check_file(f); !r.empty()) return r;
  try {
    if (YAML::LoadFile(f.string()).IsMap()) return "";
    return f.string() + ": expected a YAML mapping of keys";
  } catch (const YAML::Exception& e) {
    return fmt::format("{}: not valid YAML ({})", f.string(), e.what());
  }
}

std::string check_text_ends(const fs::path& f, const std::string& tail) {
  if (auto r = check_file(f); !r.empty()) return r;
  std::string text = slurp(f);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  if (text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0) return "";
  return fmt::format("{}: truncated (does not end with '{}')", f.string(), tail);
}

std::string first_problem(const std::vector<std::string>& reasons) {
  for (const auto& r : reasons)
    if (!r.empty()) return r;
  return "";
}

}  // namespace mill::jobs
