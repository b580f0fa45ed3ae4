// The HTML building blocks shared by the report page and `orchestrate
// compare`: one look (style), escaping, embedded PNGs, folded tables.
// Pages built with them are self-contained: pictures are data URIs.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>
#include <string>

namespace mill::report {

// The whole file as bytes ("" when it cannot be read).
std::string slurp(const std::filesystem::path& f);

// A JSON file, or null when it does not exist or does not parse.
nlohmann::json read_json(const std::filesystem::path& f);

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

// A JSON object as a two-column table (nested keys joined with dots): for
// the folded raw-data parts of a page, never for a headline.
void json_table(std::ostringstream& o, const nlohmann::json& j, const std::string& prefix = "");

// Opens a folded block (<details>) with a one-line summary; close with "</details>".
std::string fold(const std::string& summary);

}  // namespace mill::report
