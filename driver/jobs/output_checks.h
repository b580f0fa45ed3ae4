// Checks that a job's declared output files exist and parse. Each returns ""
// when the file is sound, else a short reason naming the file ("... missing",
// "... not valid JSON: ..."): a job whose outputs are damaged is not done.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mill::jobs {

// Exists and is a non-empty regular file.
std::string check_file(const std::filesystem::path& f);
// Exists as a regular file, empty or not (a marker such as case.foam).
std::string check_exists(const std::filesystem::path& f);
// A JSON object (or array when `array_ok`).
std::string check_json(const std::filesystem::path& f, bool array_ok = false);
// An HDF5 file that opens (a truncated one does not).
std::string check_hdf5(const std::filesystem::path& f);
// A YAML mapping.
std::string check_yaml_map(const std::filesystem::path& f);
// A text file whose last non-blank line ends with `tail` (e.g. "</html>").
std::string check_text_ends(const std::filesystem::path& f, const std::string& tail);

// The first non-empty reason of a list, or "".
std::string first_problem(const std::vector<std::string>& reasons);

}  // namespace mill::jobs
