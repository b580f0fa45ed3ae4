// The HTML building blocks shared by the report page and `orchestrate
// compare`: one look (style), escaping, embedded PNGs, folded tables.
// Pages built with them are self-contained: pictures are data URIs.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mill::report {

// The whole file as bytes ("" when it cannot be read).
std::string slurp(const std::filesystem::path& f);

// Input files a page could not read, with the reason: named at the top of
// the page and printed as warnings, never silently left out.
using Problems = std::vector<std::pair<std::filesystem::path, std::string>>;

// A JSON file, or null when it does not exist or does not parse; one that
// does not parse is also added to `problems` (once) when given.
nlohmann::json read_json(const std::filesystem::path& f, Problems* problems = nullptr);

// A number for a table cell with the given precision ("{:.1f}"); a value
// that is not a number (NaN, infinite: a damaged or degenerate result) reads
// "n/a", never as a huge integer.
std::string cell(double v, const char* spec, double scale = 1.0);

// v[key] or null.
nlohmann::json pick(const nlohmann::json& v, const char* key);

// Text made safe for HTML element content and attribute values.
std::string esc(const std::string& s);

// RFC 4648 base64 of bytes.
std::string base64(const std::string& in);

// <!DOCTYPE html> ... <body>: the page head with the shared style sheet.
std::string page_head(const std::string& title);

// </body></html> with the generator line.
std::string page_tail();

// A figure with the PNG embedded as a data URI and its caption.
void embed_png(std::ostringstream& o, const std::filesystem::path& png, const std::string& caption);

// The same for an image of the given MIME type ("image/gif": an animation).
void embed_image(std::ostringstream& o, const std::filesystem::path& file, const std::string& mime,
                 const std::string& caption);

// A JSON object as a two-column table (nested keys joined with dots): for
// the folded raw-data parts of a page, never for a headline.
void json_table(std::ostringstream& o, const nlohmann::json& j, const std::string& prefix = "");

// Opens a folded block (<details>) with a one-line summary; close with "</details>".
std::string fold(const std::string& summary);

}  // namespace mill::report
