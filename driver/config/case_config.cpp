// Case-file and ore-card validation: unknown keys, types, ranges, files.
#include "config/case_config.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <cctype>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>

namespace mill::config {
namespace fs = std::filesystem;

namespace {
// A case file or ore card is a page of keys; anything far larger is not one.
constexpr long long kMaxYamlBytes = 16 << 20;
// Longest case name: it names the run folder and begins file names in it.
constexpr size_t kMaxNameLength = 100;
}  // namespace

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

namespace {

std::string scalar_text(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a section";
  return "nothing";
}

// A value in a message: quoted, control characters as \\xNN (one line).
std::string shown(const std::string& v) {
  std::string o = "'";
  for (unsigned char c : v) o += std::iscntrl(c) ? fmt::format("\\x{:02x}", c) : std::string(1, static_cast<char>(c));
  return o + "'";
}

int line_of(const YAML::Node& n) { return n.Mark().line >= 0 ? n.Mark().line + 1 : 0; }

// Best "did you mean" among declared keys and sections, or "".
std::string suggest(const Schema& s, const std::string& path) {
  std::vector<std::string> candidates;
  for (const auto& k : s.keys) {
    candidates.push_back(k.path);
    std::string p = k.path;
    for (size_t dot = p.rfind('.'); dot != std::string::npos; dot = p.rfind('.')) {
      p = p.substr(0, dot);
      candidates.push_back(p);
    }
  }
  std::string best;
  size_t best_d = std::string::npos;
  const std::string leaf = path.substr(path.rfind('.') == std::string::npos ? 0 : path.rfind('.') + 1);
  for (const auto& c : candidates) {
    size_t d = edit_distance(path, c);
    // Also accept a right leaf under a wrong-looking parent (e.g. "rotor.rmp").
    const std::string cleaf = c.substr(c.rfind('.') == std::string::npos ? 0 : c.rfind('.') + 1);
    d = std::min(d, edit_distance(leaf, cleaf) + (c == path ? 0 : 1));
    // A shortened key in the right section ("breakage.in_mill.lead").
    const std::string parent = path.substr(0, path.size() - leaf.size()), cparent = c.substr(0, c.size() - cleaf.size());
    if (!leaf.empty() && parent == cparent && cleaf.rfind(leaf, 0) == 0) d = std::min<size_t>(d, 1);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  const size_t limit = std::max<size_t>(2, path.size() / 3);
  return best_d <= limit ? best : "";
}

class Validator {
 public:
  Validator(const Schema& s, std::string file, std::set<std::string> overridden = {})
      : s_(s), file_(std::move(file)), overridden_(std::move(overridden)) {}

  // Line -1 marks a value given on the command line, not in the file.
  [[noreturn]] void fail(int line, const std::string& key, const std::string& msg) const {
    if (line < 0) throw ConfigError(fmt::format("command line (overrides {}): {}: {}", file_, key, msg));
    throw ConfigError(fmt::format("{}:{}: {}: {}", file_, line, key, msg));
  }

  // Walk a mapping node; `prefix` is the dotted path of the section.
  void walk(const YAML::Node& map, const std::string& prefix, std::map<std::string, YAML::Node>& out,
            std::map<std::string, int>& lines) {
    for (auto it = map.begin(); it != map.end(); ++it) {
      const std::string name = it->first.as<std::string>();
      const std::string path = prefix.empty() ? name : prefix + "." + name;
      const int line = overridden_.count(path) ? -1 : line_of(it->first);
      const KeyDef* k = s_.find(path);
      if (k) {
        check_value(*k, it->second, line);
        if (out.count(path)) fail(line, path, "given twice");
        out[path] = it->second;
        lines[path] = line;
      } else if (s_.is_section(path)) {
        if (!it->second.IsMap())
          fail(line, path, fmt::format("expected a section of keys, got {}", scalar_text(it->second)));
        walk(it->second, path, out, lines);
      } else {
        std::string hint = suggest(s_, path);
        fail(line, path,
             fmt::format("unknown key in {}{}", s_.what,
                         hint.empty() ? " (see docs/config.md)" : "; did you mean '" + hint + "'?"));
      }
    }
  }

  void check_number(const KeyDef& k, const YAML::Node& n, int line, const std::string& label, bool integer) {
    if (!n.IsScalar()) fail(line, label, fmt::format("expected {}, got {}", expected_text(k), scalar_text(n)));
    double v = 0;
    try {
      if (integer) {
        long i = n.as<long>();
        v = static_cast<double>(i);
      } else {
        v = n.as<double>();
      }
    } catch (const YAML::Exception&) {
      fail(line, label, fmt::format("expected {}, got {}", expected_text(k), scalar_text(n)));
    }
    if (!std::isfinite(v)) fail(line, label, fmt::format("expected a finite {}, got {}", expected_text(k), scalar_text(n)));
    bool bad = false;
    if (k.min) bad |= k.min_exclusive ? !(v > *k.min) : !(v >= *k.min);
    if (k.max) bad |= k.max_exclusive ? !(v < *k.max) : !(v <= *k.max);
    if (bad) {
      const std::string hint = slip_hint(k, v);
      fail(line, label,
           fmt::format("expected {}, got {}{}", expected_text(k), n.Scalar(), hint.empty() ? "" : "; did you mean " + hint + "?"));
    }
  }

  // Names of keys of this file that have a plausible range (allow_outside_range).
  void check_key_list(const KeyDef& k, const YAML::Node& n, int line) {
    if (!n.IsSequence() || n.size() == 0)
      fail(line, k.path, fmt::format("expected {} (e.g. [{}]), got {}", expected_text(k), first_plausible(), scalar_text(n)));
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string label = fmt::format("{}[{}]", k.path, i);
      const int l = line < 0 ? line : (line_of(n[i]) ? line_of(n[i]) : line);
      if (!n[i].IsScalar()) fail(l, label, fmt::format("expected a key name, got {}", scalar_text(n[i])));
      const KeyDef* named = s_.find(n[i].Scalar());
      if (!named || !named->plausible) {
        const std::string hint = suggest(s_, n[i].Scalar());
        fail(l, label,
             fmt::format("{} is not a key of the {} with a plausible range{}", shown(n[i].Scalar()), s_.what,
                         hint.empty() ? " (docs/config.md, \"Plausible ranges\")" : "; did you mean '" + hint + "'?"));
      }
    }
  }

  std::string first_plausible() const {
    for (const auto& k : s_.keys)
      if (k.plausible) return k.path;
    return "";
  }

  void check_value(const KeyDef& k, const YAML::Node& n, int line) {
    switch (k.type) {
      case KeyType::Int: check_number(k, n, line, k.path, true); break;
      case KeyType::Real: check_number(k, n, line, k.path, false); break;
      case KeyType::Bool:
        try {
          if (!n.IsScalar()) throw YAML::Exception(YAML::Mark(), "");
          (void)n.as<bool>();
        } catch (const YAML::Exception&) {
          fail(line, k.path, fmt::format("expected true or false, got {}", scalar_text(n)));
        }
        break;
      case KeyType::String:
      case KeyType::Path:
        if (!n.IsScalar() || n.Scalar().empty())
          fail(line, k.path, fmt::format("expected {}, got {}", type_name(k.type), scalar_text(n)));
        if (!k.pattern.empty() && !std::regex_match(n.Scalar(), std::regex(k.pattern)))
          fail(line, k.path, fmt::format("expected {}, got {}", expected_text(k), shown(n.Scalar())));
        break;
      case KeyType::Choice:
        if (!n.IsScalar() || std::find(k.choices.begin(), k.choices.end(), n.Scalar()) == k.choices.end())
          fail(line, k.path, fmt::format("expected {}, got {}", expected_text(k), scalar_text(n)));
        break;
      case KeyType::KeyList: check_key_list(k, n, line); break;
      case KeyType::RealList:
      case KeyType::IntList: {
        const bool integer = k.type == KeyType::IntList;
        if (n.IsScalar()) {
          check_number(k, n, line, k.path, integer);
        } else if (n.IsSequence()) {
          if (n.size() == 0) fail(line, k.path, fmt::format("expected a non-empty {}, got []", type_name(k.type)));
          for (size_t i = 0; i < n.size(); ++i)
            check_number(k, n[i], line < 0 ? line : (line_of(n[i]) ? line_of(n[i]) : line), fmt::format("{}[{}]", k.path, i),
                         integer);
        } else {
          fail(line, k.path, fmt::format("expected {}, got {}", type_name(k.type), scalar_text(n)));
        }
        break;
      }
    }
  }

 private:
  const Schema& s_;
  std::string file_;
  std::set<std::string> overridden_;
};

}  // namespace

namespace {

// A carriage return without a line feed ends no line for yaml-cpp: in a file
// with CR-only line endings the first comment swallows the whole file.
void check_line_endings(const std::string& text, const std::string& file_label) {
  int line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') ++line;
    if (text[i] != '\r' || (i + 1 < text.size() && text[i + 1] == '\n')) continue;
    if (text.find('\n') == std::string::npos)
      throw ConfigError(fmt::format("{}: line endings are CR only (an old Mac text file), so YAML reads the file as one "
                                    "line; expected LF or CRLF line endings: convert with tr '\\r' '\\n' < {} > fixed.yaml",
                                    file_label, file_label));
    throw ConfigError(fmt::format("{}:{}: the line ends with a carriage return (CR) alone, so YAML joins it to the next; "
                                  "expected LF or CRLF line endings: convert with tr '\\r' '\\n' < {} > fixed.yaml",
                                  file_label, line, file_label));
  }
}

// Line of the '---' that starts the second YAML document (0 if not found).
int second_document_line(const std::string& text) {
  std::istringstream in(text);
  std::string l;
  int n = 0;
  bool content = false;
  while (std::getline(in, l)) {
    ++n;
    const bool marker = l.rfind("---", 0) == 0 && (l.size() == 3 || std::isspace(static_cast<unsigned char>(l[3])));
    if (marker && content) return n;
    const size_t first = l.find_first_not_of(" \t");
    if (marker || (first != std::string::npos && l[first] != '#')) content = true;
  }
  return 0;
}

// The one YAML document of a file: a ConfigError for bad YAML, several
// documents, or a file that holds nothing.
YAML::Node load_one_document(const std::string& text, const std::string& file_label, const Schema& schema) {
  check_line_endings(text, file_label);
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(fmt::format("{}:{}: not valid YAML: {}", file_label, e.mark.line + 1, e.msg));
  }
  if (docs.size() > 1)
    throw ConfigError(fmt::format("{}:{}: a second YAML document starts here ('---'; {} documents in all); expected one "
                                  "{}: merge them or keep one",
                                  file_label, second_document_line(text), docs.size(), schema.what));
  if (docs.empty() || docs[0].IsNull()) {
    std::string required;
    for (const auto& k : schema.keys)
      if (k.default_yaml.empty() && !k.optional) required += (required.empty() ? "" : ", ") + k.path;
    throw ConfigError(fmt::format("{}: holds no keys (empty, or only comments); expected {} {} with at least: {}",
                                  file_label, std::string("aeiou").find(schema.what[0]) == std::string::npos ? "a" : "an",
                                  schema.what, required));
  }
  if (!docs[0].IsMap())
    throw ConfigError(fmt::format("{}:1: expected a YAML mapping of keys at the top level", file_label));
  return docs[0];
}

}  // namespace

Document Document::parse(const std::string& text, const std::string& file_label, const Schema& schema,
                         const std::vector<std::pair<std::string, std::string>>& overrides) {
  Document d;
  d.file_ = file_label;
  d.schema_ = &schema;
  YAML::Node root = load_one_document(text, file_label, schema);
  for (const auto& [path, value] : overrides) {
    // Walk/create the sections of the dotted path, then set the leaf.
    std::vector<YAML::Node> chain{root};
    size_t start = 0;
    for (size_t dot = path.find('.'); dot != std::string::npos; start = dot + 1, dot = path.find('.', start)) {
      const std::string part = path.substr(start, dot - start);
      if (!chain.back()[part] || !chain.back()[part].IsMap()) chain.back()[part] = YAML::Node(YAML::NodeType::Map);
      chain.push_back(chain.back()[part]);
    }
    chain.back()[path.substr(start)] = YAML::Load(value);
  }
  std::set<std::string> overridden;
  for (const auto& o : overrides) overridden.insert(o.first);
  Validator v(schema, file_label, overridden);
  v.walk(root, "", d.values_, d.lines_);
  for (const auto& k : schema.keys) {
    if (d.values_.count(k.path) || k.default_if) continue;
    if (!k.default_yaml.empty()) {
      d.values_[k.path] = YAML::Load(k.default_yaml);
      d.lines_[k.path] = 0;
    } else if (!k.optional) {
      throw ConfigError(fmt::format("{}: {}: required key is missing; expected {} ({})", file_label, k.path,
                                    expected_text(k), k.doc));
    }
  }
  // The defaults that follow another key, once every plain default is in.
  for (const auto& k : schema.keys) {
    if (d.values_.count(k.path) || !k.default_if) continue;
    const auto other = d.values_.find(k.default_if->when);
    const bool met = other != d.values_.end() && other->second.IsScalar() &&
                     other->second.Scalar() == k.default_if->is;
    d.values_[k.path] = YAML::Load(met ? k.default_if->yaml : k.default_yaml);
    d.lines_[k.path] = 0;
  }
  d.check_plausible();
  return d;
}

// Every value against its key's plausible range: outside it is an error that
// names the likely unit slip, unless the file lists the key in
// allow_outside_range; such an outlier is kept in outliers().
void Document::check_plausible() {
  std::set<std::string> allowed;
  if (values_.count(kAllowOutsideRange))
    for (const auto& n : values_.at(kAllowOutsideRange)) allowed.insert(n.Scalar());
  outliers_ = nlohmann::json::array();
  for (const auto& k : schema_->keys) {
    if (!k.plausible || !values_.count(k.path)) continue;
    const Plausible& p = *k.plausible;
    const std::vector<double> v = reals(k.path);
    const std::string unit = k.unit.empty() ? "" : " " + k.unit;
    for (size_t i = 0; i < v.size(); ++i) {
      if (v[i] >= p.lo && v[i] <= p.hi) continue;
      if (allowed.count(k.path)) {
        outliers_.push_back({{"file", file_}, {"key", k.path}, {"value", v[i]}, {"unit", k.unit}, {"plausible", {p.lo, p.hi}}});
        continue;
      }
      const std::string label = where(k.path) + (values_.at(k.path).IsSequence() ? fmt::format("[{}]", i) : "");
      const std::string hint = slip_hint(k, v[i]);
      throw ConfigError(fmt::format(
          "{}: {}{}: {}expected {} in [{}, {}]{} ({}); a deliberate outlier: list {} in {} of this {}", label, num(v[i]),
          unit, hint.empty() ? "outside the plausible range; " : "did you mean " + hint + "? ", p.what, num(p.lo),
          num(p.hi), unit, p.source, k.path, kAllowOutsideRange, schema_->what));
    }
  }
}

std::string read_regular_file(const fs::path& file, const std::string& what) {
  // stat first: a directory reads as empty and a FIFO blocks in open().
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) {
    if (errno == ENOENT) throw ConfigError(fmt::format("{}: {} not found", file.string(), what));
    if (errno == ELOOP)
      throw ConfigError(fmt::format("{}: a loop of symbolic links; expected a {} (a YAML file)", file.string(), what));
    throw ConfigError(fmt::format("{}: cannot open {}: {}", file.string(), what, std::strerror(errno)));
  }
  if (S_ISDIR(st.st_mode))
    throw ConfigError(fmt::format("{}: is a directory; expected a {} (a YAML file)", file.string(), what));
  if (!S_ISREG(st.st_mode))
    throw ConfigError(fmt::format("{}: is not a regular file (a FIFO, socket or device); expected a {} (a YAML file)",
                                  file.string(), what));
  if (st.st_size > kMaxYamlBytes)
    throw ConfigError(fmt::format("{}: {} bytes; expected a {} of at most {} bytes", file.string(), st.st_size, what,
                                  kMaxYamlBytes));
  // Non-blocking: the path may have been swapped for a FIFO since the stat.
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw ConfigError(fmt::format("{}: cannot open {}: {}", file.string(), what, std::strerror(errno)));
  struct stat st2 {};
  if (::fstat(fd, &st2) != 0 || !S_ISREG(st2.st_mode)) {
    ::close(fd);
    throw ConfigError(fmt::format("{}: is not a regular file; expected a {} (a YAML file)", file.string(), what));
  }
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      throw ConfigError(fmt::format("{}: cannot read {}: {}", file.string(), what, std::strerror(e)));
    }
    if (n == 0) break;
    text.append(buf, static_cast<size_t>(n));
    if (static_cast<long long>(text.size()) > kMaxYamlBytes) break;
  }
  ::close(fd);
  return text;
}

Document Document::load(const fs::path& file, const Schema& schema) {
  return parse(read_regular_file(file, schema.what), file.string(), schema);
}

const KeyDef& Document::def(const std::string& path) const {
  const KeyDef* k = schema_ ? schema_->find(path) : nullptr;
  if (!k) throw std::logic_error("undeclared config key requested: " + path);
  return *k;
}

bool Document::has(const std::string& path) const {
  def(path);
  return values_.count(path) > 0;
}

namespace {
const YAML::Node& need(const std::map<std::string, YAML::Node>& m, const std::string& path) {
  auto it = m.find(path);
  if (it == m.end()) throw std::logic_error("optional config key read without has(): " + path);
  return it->second;
}
}  // namespace

double Document::real(const std::string& path) const {
  def(path);
  return need(values_, path).as<double>();
}
long Document::integer(const std::string& path) const {
  def(path);
  return need(values_, path).as<long>();
}
bool Document::boolean(const std::string& path) const {
  def(path);
  return need(values_, path).as<bool>();
}
std::string Document::str(const std::string& path) const {
  def(path);
  return need(values_, path).as<std::string>();
}
std::vector<double> Document::reals(const std::string& path) const {
  def(path);
  const YAML::Node& n = need(values_, path);
  if (n.IsScalar()) return {n.as<double>()};
  std::vector<double> v;
  for (const auto& x : n) v.push_back(x.as<double>());
  return v;
}
int Document::line(const std::string& path) const {
  auto it = lines_.find(path);
  return it == lines_.end() ? 0 : it->second;
}
std::string Document::where(const std::string& path) const {
  const int l = line(path);
  if (l < 0) return fmt::format("command line (overrides {}): {}", file_, path);
  return l > 0 ? fmt::format("{}:{}: {}", file_, l, path) : fmt::format("{}: {} (default)", file_, path);
}

nlohmann::json Document::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [path, node] : values_) {
    const KeyDef& k = def(path);
    switch (k.type) {
      case KeyType::Int: j[path] = node.as<long>(); break;
      case KeyType::Real: j[path] = node.as<double>(); break;
      case KeyType::Bool: j[path] = node.as<bool>(); break;
      case KeyType::RealList:
      case KeyType::IntList: j[path] = reals(path); break;
      case KeyType::KeyList:
        j[path] = nlohmann::json::array();
        for (const auto& n : node) j[path].push_back(n.Scalar());
        break;
      default: j[path] = node.as<std::string>(); break;
    }
  }
  return j;
}

nlohmann::json ore_keys(const Document& ore) {
  nlohmann::json all = ore.to_json(), out = nlohmann::json::object();
  const auto is_check = [](const std::string& k) {
    return std::find(std::begin(kOreCheckKeys), std::end(kOreCheckKeys), k) != std::end(kOreCheckKeys);
  };
  for (auto it = all.begin(); it != all.end(); ++it)
    if (it.key() != "name" && it.key() != "source" && it.key().rfind("calibrated.", 0) != 0 &&
        it.key().rfind("jk.", 0) != 0 && it.key() != kAllowOutsideRange && !is_check(it.key()) &&
        it.key() != "rock_class" && it.key() != "direct_tensile_strength")
      out[it.key()] = it.value();
  return out;
}

void check_ore(const Document& ore) {
  if (ore.real("ucs") <= ore.real("tensile_strength"))
    throw ConfigError(fmt::format("{}: expected ucs > tensile_strength (rocks: ucs/tensile ~ 5-20), got ucs {:g} Pa <= {:g} Pa",
                                  ore.where("ucs"), ore.real("ucs"), ore.real("tensile_strength")));
  for (const auto& [given, other] : {std::pair<const char*, const char*>{"jk.A", "jk.b"}, {"jk.b", "jk.A"}})
    if (ore.has(given) && !ore.has(other))
      throw ConfigError(fmt::format("{}: {} is given without {}: a measured JK pair needs both (or remove {})",
                                    ore.where(given), given, other, given));
}

namespace {

constexpr double kPi = 3.14159265358979323846;
// Highest flywheel tip speed accepted: a steel rim's hoop stress rho v^2
// reaches its strength (~700 MPa at 7850 kg/m^3) near 300 m/s.
constexpr double kMaxTipSpeed = 300.0;
// Most steps a transport run may take (how far a lump may move in one step:
// kMaxLumpStepMove).
constexpr double kMaxSteps = 1e9;

// A list key's items given twice: each one is a job (or part of a job
// label), so a repeated item would run twice into one folder.
void check_unique_items(const Document& d, const std::string& key, const char* unit) {
  const auto v = d.reals(key);
  for (size_t i = 0; i < v.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (v[i] == v[j])
        throw ConfigError(fmt::format("{}[{}]: {:g} {} is listed twice (also item {}): expected each value once",
                                      d.where(key), i, v[i], unit, j));
}

// Values that pass the schema one by one but make no physical sense, alone
// or together: speeds no mill reaches, lumps bigger than the beaters, time
// steps longer than the run or than a lump may move in one step.
void check_physics(const Document& d) {
  auto fail = [&](const std::string& key, const std::string& msg) {
    throw ConfigError(fmt::format("{}: {}", d.where(key), msg));
  };
  const double D = d.real("mill.flywheel.diameter"), hub = d.real("mill.flywheel.hub_diameter");
  const auto rpms = d.reals("rotor.rpm");
  double tip_max = 0;
  for (size_t i = 0; i < rpms.size(); ++i) {
    const double tip = kPi * D * rpms[i] / 60.0;
    tip_max = std::max(tip_max, tip);
    if (tip > kMaxTipSpeed)
      throw ConfigError(fmt::format(
          "{}[{}]: a {:g} m flywheel at {:g} rpm has a tip speed of {:.0f} m/s; expected at most {:g} m/s (beater "
          "mills run at 50-150 m/s; a steel rim bursts near {:g} m/s): at this diameter, rotor.rpm <= {:.0f}",
          d.where("rotor.rpm"), i, D, rpms[i], tip, kMaxTipSpeed, kMaxTipSpeed, kMaxTipSpeed * 60.0 / (kPi * D)));
  }
  // The flat joint's layout fits its slots; broken_contact is the parallel bond's.
  if (d.str("lump.bond_model") == "flat_joint") {
    const long rings = d.integer("lump.joint_rings"), sectors = d.integer("lump.joint_sectors");
    if (rings * sectors > kMaxJointElements)
      throw ConfigError(fmt::format(
          "{}: {} rings x {} sectors is {} elements per interface; expected at most {} (fix bond/flatjoint): "
          "lower lump.joint_rings or lump.joint_sectors",
          d.where("lump.joint_sectors"), rings, sectors, rings * sectors, kMaxJointElements));
    if (d.boolean("lump.broken_contact"))
      throw ConfigError(fmt::format(
          "{}: an option of the parallel bond, not of lump.bond_model: flat_joint (a flat joint's broken "
          "elements always stay as frictional contacts); expected false or absent: remove it, or set "
          "lump.bond_model: parallel",
          d.where("lump.broken_contact")));
  } else if (d.has("lump.joint_friction")) {
    throw ConfigError(fmt::format(
        "{}: the friction of a flat joint's broken elements, and lump.bond_model is parallel; expected it "
        "absent: remove it, or set lump.bond_model: flat_joint",
        d.where("lump.joint_friction")));
  }
  check_unique_items(d, "rotor.rpm", "rpm");
  check_unique_items(d, "breakage.velocities", "m/s");
  if (d.has("breakage.strength_velocities")) {
    check_unique_items(d, "breakage.strength_velocities", "m/s");
    if (d.str("breakage.conditions") != "transport")
      throw ConfigError(fmt::format(
          "{}: strength impacts go beside stage 1's impact conditions, and breakage.conditions is "
          "sweep; expected it absent (list the speeds in breakage.velocities) or "
          "breakage.conditions: transport",
          d.where("breakage.strength_velocities")));
  }
  check_unique_items(d, "breakage.angles", "deg");
  if (d.has("breakage.crossing_velocities")) {
    check_unique_items(d, "breakage.crossing_velocities", "m/s");
    const std::string where = d.where("breakage.crossing_velocities");
    if (d.str("breakage.conditions") != "sweep")
      throw ConfigError(fmt::format(
          "{}: more repeats at speeds of the sweep, and breakage.conditions is {}; expected it "
          "absent, or breakage.conditions: sweep",
          where, d.str("breakage.conditions")));
    const auto sweep = d.reals("breakage.velocities");
    for (double v : d.reals("breakage.crossing_velocities"))
      if (std::find(sweep.begin(), sweep.end(), v) == sweep.end())
        throw ConfigError(fmt::format(
            "{}: {} m/s is not a speed of breakage.velocities; expected speeds of the sweep "
            "(add {} to breakage.velocities, or drop it here)",
            where, num(v), num(v)));
    if (d.integer("breakage.crossing_repeats") < d.integer("breakage.repeats"))
      throw ConfigError(fmt::format(
          "{}: {} repeats at the crossing, fewer than breakage.repeats ({}); expected at least {}",
          d.where("breakage.crossing_repeats"), d.integer("breakage.crossing_repeats"),
          d.integer("breakage.repeats"), d.integer("breakage.repeats")));
  }

  // The lump against the beaters: a plate reaches (D - hub) / 2 from the hub.
  const double plate = (D - hub) / 2;
  for (const char* key : {"injection.lump_diameter", "lump.diameter"})
    if (d.real(key) >= plate)
      fail(key, fmt::format("a {:g} m lump is not smaller than the beater plates ({:g} m from hub to tip: "
                            "mill.flywheel.diameter {:g} m, hub_diameter {:g} m); expected a lump smaller than {:g} m",
                            d.real(key), plate, D, hub, plate));

  // Transport: the run must outlast the injection and hold many steps.
  const double duration = d.real("injection.duration"), t_limit = d.real("injection.time_limit");
  const double dt = d.real("injection.timestep");
  if (!(t_limit > duration))
    fail("injection.time_limit", fmt::format("expected longer than injection.duration ({:g} s), got {:g} s: the run "
                                             "would stop before every lump is in",
                                             duration, t_limit));
  if (dt > t_limit / 10)
    fail("injection.timestep", fmt::format("expected at most a tenth of injection.time_limit ({:g} s), got {:g} s",
                                           t_limit, dt));
  if (t_limit / dt > kMaxSteps)
    fail("injection.timestep", fmt::format("{:g} s over injection.time_limit {:g} s is {:.3g} steps; expected at most "
                                           "{:g} steps (a step of at least {:.3g} s)",
                                           dt, t_limit, t_limit / dt, kMaxSteps, t_limit / kMaxSteps));
  // A lump flung at the tip speed may move a fraction of its radius per step,
  // or it passes through a beater plate between two contact checks.
  const double r_lump = d.real("injection.lump_diameter") / 2;
  if (tip_max * dt > kMaxLumpStepMove * r_lump)
    fail("injection.timestep", fmt::format("at the tip speed {:.0f} m/s a lump moves {:.3g} m per "
                                           "step, more than {:g} of its radius ({:g} m); "
                                           "expected injection.timestep <= {:.3g} s",
                                           tip_max, tip_max * dt, kMaxLumpStepMove, r_lump,
                                           kMaxLumpStepMove * r_lump / tip_max));
  if (d.real("transport.trajectory_interval") >= t_limit)
    fail("transport.trajectory_interval",
         fmt::format("expected shorter than injection.time_limit ({:g} s), got {:g} s: no trajectory point would be kept",
                     t_limit, d.real("transport.trajectory_interval")));

  // Sampling: a grid needs at least 3 points across the narrowest housing side.
  const double side = std::min({d.real("mill.housing.width"), d.real("mill.housing.height"), d.real("mill.housing.depth")});
  if (d.real("sample.spacing") > side / 2)
    fail("sample.spacing", fmt::format("expected at most half the narrowest housing side ({:g} m of {:g} m), got {:g} m",
                                       side / 2, side, d.real("sample.spacing")));

  // The outlet's absolute pressure must stay above vacuum.
  if (d.real("gas.outlet_pressure_drop") >= d.real("gas.pressure"))
    fail("gas.outlet_pressure_drop",
         fmt::format("expected less than gas.pressure ({:g} Pa): the outlet would be at or below vacuum, got {:g} Pa",
                     d.real("gas.pressure"), d.real("gas.outlet_pressure_drop")));

  // In-mill breakage starts from stage 1's strikes and must outlast its lead.
  if (d.integer("breakage.in_mill.lumps") > 0 && d.str("breakage.conditions") != "transport")
    fail("breakage.in_mill.lumps",
         fmt::format("in-mill breakage starts from stage 1's flywheel strikes; expected breakage.conditions: transport "
                     "(got {}), or breakage.in_mill.lumps: 0, got {}",
                     d.str("breakage.conditions"), d.integer("breakage.in_mill.lumps")));
  if (d.real("breakage.in_mill.lead_time") >= d.real("breakage.in_mill.duration"))
    fail("breakage.in_mill.lead_time",
         fmt::format("expected shorter than breakage.in_mill.duration ({:g} s): the run would end before the strike, "
                     "got {:g} s",
                     d.real("breakage.in_mill.duration"), d.real("breakage.in_mill.lead_time")));

  // Breakage: a given time step must be well inside the simulated time.
  const double after = d.real("breakage.duration_after_contact"), bdt = d.real("breakage.timestep");
  if (bdt > after / 10)
    fail("breakage.timestep", fmt::format("expected 0 (automatic) or at most a tenth of breakage.duration_after_contact "
                                          "({:g} s), got {:g} s",
                                          after, bdt));
  // The adaptive step (on by default) acts on the automatic step only; asked
  // for in the file or on the command line (--set) together with a given
  // step, it is a contradiction.
  if (d.boolean("breakage.adaptive_step") && d.line("breakage.adaptive_step") != 0 && bdt > 0)
    fail("breakage.adaptive_step",
         fmt::format(
             "the adaptive step re-evaluates the automatic step; expected breakage.timestep: 0 "
             "(automatic) with it, or breakage.adaptive_step: false, got breakage.timestep {:g} s",
             bdt));
}

// Plan limits (docs/errors.md, "Plan limits"): a stage of more jobs, a run
// of more dump files or a field of more grid points than these is refused
// before any plan is built, as a typo (an extra 0, e-6 for e-3) and not a
// campaign anyone meant.
constexpr double kMaxJobs = 1e5;
constexpr double kMaxDumps = 1000;
constexpr double kMaxGridPoints = 2e7;

// The breakage stage's job count, from the keys alone (transport conditions:
// at most velocity_bins per rotor speed); names the key that drives it.
void check_job_count(const Document& d) {
  const double rpms = static_cast<double>(d.reals("rotor.rpm").size());
  const double repeats = static_cast<double>(d.integer("breakage.repeats"));
  std::vector<std::pair<std::string, double>> factors;
  double jobs = 0;
  std::string how;
  if (d.str("breakage.conditions") == "sweep") {
    const double nv = static_cast<double>(d.reals("breakage.velocities").size());
    const double na = static_cast<double>(d.reals("breakage.angles").size());
    jobs = nv * na * repeats;
    how = fmt::format("breakage.velocities ({}) x breakage.angles ({}) x breakage.repeats ({})", nv, na, repeats);
    factors = {{"breakage.velocities", nv}, {"breakage.angles", na}, {"breakage.repeats", repeats}};
    if (d.has("breakage.crossing_velocities")) {  // (only sweep speeds: checked before)
      const double nc = static_cast<double>(d.reals("breakage.crossing_velocities").size());
      const double more = static_cast<double>(d.integer("breakage.crossing_repeats")) - repeats;
      jobs += nc * na * more;
      how += fmt::format(" + breakage.crossing_velocities ({}) x breakage.angles x {} more repeats",
                         nc, more);
      factors.push_back({"breakage.crossing_repeats", more});
    }
  } else {
    const double bins = static_cast<double>(d.integer("breakage.velocity_bins"));
    const double lumps = static_cast<double>(d.integer("breakage.in_mill.lumps"));
    const double strength =
        d.has("breakage.strength_velocities")
            ? static_cast<double>(d.reals("breakage.strength_velocities").size())
            : 0;
    jobs = rpms * (bins * repeats + lumps) + strength * repeats;
    how = fmt::format(
        "rotor.rpm ({}) x (breakage.velocity_bins ({}) x breakage.repeats ({}) + "
        "breakage.in_mill.lumps ({}))"
        " + breakage.strength_velocities ({}) x breakage.repeats",
        rpms, bins, repeats, lumps, strength);
    factors = {{"breakage.velocity_bins", bins},
               {"breakage.repeats", repeats},
               {"breakage.in_mill.lumps", lumps},
               {"rotor.rpm", rpms},
               {"breakage.strength_velocities", strength}};
  }
  if (jobs <= kMaxJobs) return;
  const auto largest = std::max_element(factors.begin(), factors.end(),
                                        [](const auto& a, const auto& b) { return a.second < b.second; });
  throw ConfigError(fmt::format("{}: the breakage stage would have {} jobs ({}); expected at most {} jobs in a stage "
                                "(docs/errors.md, \"Plan limits\"): lower {}",
                                d.where(largest->first), num(jobs), how, num(kMaxJobs), largest->first));
}

// Output intervals: at least one time step, and at most kMaxDumps files per run.
void check_intervals(const Document& d) {
  auto fail = [&](const std::string& key, const std::string& msg) {
    throw ConfigError(fmt::format("{}: {}", d.where(key), msg));
  };
  const double dt = d.real("injection.timestep"), t_limit = d.real("injection.time_limit");
  for (const char* key : {"transport.trajectory_interval", "transport.vtk_interval"}) {
    const double every = d.real(key);
    if (every > 0 && every < dt)
      fail(key, fmt::format("{} s is below one time step (injection.timestep {} s): a record every step; expected 0 (none) "
                            "or at least {} s",
                            num(every), num(dt), num(dt)));
  }
  const double vtk = d.real("transport.vtk_interval");
  if (vtk > 0 && t_limit / vtk > kMaxDumps)
    fail("transport.vtk_interval",
         fmt::format("{} s over injection.time_limit {} s is {} VTK dumps; expected at most {} (an interval of at least {} s, "
                     "or 0 for none)",
                     num(vtk), num(t_limit), num(t_limit / vtk), num(kMaxDumps), num(t_limit / kMaxDumps)));
  const double dump = d.real("breakage.dump_interval"), bdt = d.real("breakage.timestep");
  const double run = std::max(d.real("breakage.duration_after_contact"),
                              d.integer("breakage.in_mill.lumps") > 0 ? d.real("breakage.in_mill.duration") : 0.0);
  if (dump > 0 && bdt > 0 && dump < bdt)
    fail("breakage.dump_interval", fmt::format("{} s is below one time step (breakage.timestep {} s): a dump every step; "
                                               "expected 0 (none) or at least {} s",
                                               num(dump), num(bdt), num(bdt)));
  if (dump > 0 && run / dump > kMaxDumps)
    fail("breakage.dump_interval",
         fmt::format("{} s over a run of {} s is {} VTK dumps per run; expected at most {} (an interval of at least {} s, "
                     "or 0 for none)",
                     num(dump), num(run), num(run / dump), num(kMaxDumps), num(run / kMaxDumps)));
  if (bdt > 0 && run / bdt > kMaxSteps)
    fail("breakage.timestep", fmt::format("{} s over a run of {} s is {} steps; expected at most {} steps (a step of at "
                                          "least {} s, or 0: automatic)",
                                          num(bdt), num(run), num(run / bdt), num(kMaxSteps), num(run / kMaxSteps)));
}

// Plans and runs of a bounded size: job counts, dump files, grid points.
void check_plan_bounds(const Document& d) {
  check_job_count(d);
  check_intervals(d);
  const double W = d.real("mill.housing.width"), H = d.real("mill.housing.height"), D = d.real("mill.housing.depth");
  const double s = d.real("sample.spacing");
  const double points = (std::floor(W / s) + 1) * (std::floor(H / s) + 1) * (std::floor(D / s) + 1);
  if (points > kMaxGridPoints)
    throw ConfigError(fmt::format("{}: {} m over the {} x {} x {} m housing is {} grid points; expected at most {} "
                                  "(docs/errors.md, \"Plan limits\"): a spacing of at least {} m",
                                  d.where("sample.spacing"), num(s), num(W), num(H), num(D), num(points),
                                  num(kMaxGridPoints), num(std::cbrt(W * H * D / kMaxGridPoints) * 1.01)));
}

// Cross-key checks of a case: the geometry must fit, lists must be ordered.
void check_case(const Document& d) {
  auto fail = [&](const std::string& key, const std::string& msg) {
    throw ConfigError(fmt::format("{}: {}", d.where(key), msg));
  };
  const double D = d.real("mill.flywheel.diameter"), W = d.real("mill.housing.width");
  const double H = d.real("mill.housing.height");
  if (d.real("mill.flywheel.hub_diameter") >= D)
    fail("mill.flywheel.hub_diameter", fmt::format("expected less than mill.flywheel.diameter ({:g} m), got {:g} m", D,
                                                   d.real("mill.flywheel.hub_diameter")));
  if (std::abs(d.real("mill.flywheel.axis_x")) + D / 2 >= W / 2)
    fail("mill.flywheel.diameter", fmt::format("flywheel ({:g} m at x = {:g} m) does not fit in the housing width {:g} m", D,
                                               d.real("mill.flywheel.axis_x"), W));
  const double ah = d.real("mill.flywheel.axis_height");
  if (ah - D / 2 <= 0 || ah + D / 2 >= H)
    fail("mill.flywheel.axis_height",
         fmt::format("flywheel (diameter {:g} m) must fit between floor and roof (height {:g} m), got axis at {:g} m", D, H, ah));
  if (d.real("mill.flywheel.plate_width") >= d.real("mill.housing.depth"))
    fail("mill.flywheel.plate_width", fmt::format("expected less than mill.housing.depth ({:g} m), got {:g} m",
                                                  d.real("mill.housing.depth"), d.real("mill.flywheel.plate_width")));
  for (const char* side : {"inlet", "outlet"}) {
    const std::string c = fmt::format("mill.{}.center_x", side), s = fmt::format("mill.{}.size", side);
    if (std::abs(d.real(c)) + d.real(s) / 2 > W / 2 || d.real(s) > d.real("mill.housing.depth"))
      fail(s, fmt::format("the {} ({:g} m at x = {:g} m) must lie on the housing ({:g} m wide, {:g} m deep)", side, d.real(s),
                          d.real(c), W, d.real("mill.housing.depth")));
  }
  const auto edges = d.reals("breakage.size_fraction_edges");
  if (edges.size() < 2) fail("breakage.size_fraction_edges", "expected at least two edges (one fraction)");
  for (size_t i = 1; i < edges.size(); ++i)
    if (edges[i] <= edges[i - 1])
      fail("breakage.size_fraction_edges",
           fmt::format("expected strictly ascending edges, got {:g} after {:g} (item {})", edges[i], edges[i - 1], i));
  if (d.real("injection.lump_diameter") >= d.real("mill.inlet.size"))
    fail("injection.lump_diameter", fmt::format("expected smaller than the inlet ({:g} m), got {:g} m",
                                                d.real("mill.inlet.size"), d.real("injection.lump_diameter")));
  check_physics(d);
  check_plan_bounds(d);
}

// The case name becomes the run folder runs/<name> and the start of file
// names in it: one plain path component, short enough for any file system.
void check_name(const Document& d) {
  const std::string name = d.str("name");
  for (char ch : name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.'))
      throw ConfigError(fmt::format("{}: expected letters, digits, '-', '_' or '.', got {}", d.where("name"), shown(name)));
  if (!std::isalnum(static_cast<unsigned char>(name[0])))
    throw ConfigError(fmt::format("{}: expected a name that starts with a letter or digit (it names the run folder "
                                  "runs/<name>), got '{}'",
                                  d.where("name"), name));
  if (name.size() > kMaxNameLength)
    throw ConfigError(fmt::format("{}: a name of {} characters; expected at most {} (it names the run folder runs/<name>, "
                                  "and a file name may have at most 255): '{}...'",
                                  d.where("name"), name.size(), kMaxNameLength, name.substr(0, 20)));
}

// Ore card path: absolute; else relative to the case file; else to the project.
fs::path resolve_ore(const Document& d, const fs::path& case_file, const fs::path& project_dir) {
  const fs::path p = d.str("ore.card");
  std::vector<fs::path> tried;
  if (p.is_absolute()) {
    tried.push_back(p);
  } else {
    tried.push_back(case_file.parent_path() / p);
    tried.push_back(project_dir / p);
    tried.push_back(project_dir / "liggghts_inputs" / "materials" / p);
    tried.push_back(project_dir / "liggghts_inputs" / "materials" / (p.string() + ".yaml"));
  }
  std::error_code ec;
  for (const auto& t : tried)
    if (fs::is_regular_file(t, ec)) return fs::weakly_canonical(t);
  for (const auto& t : tried) {
    if (!fs::exists(t, ec) && ec == std::errc::too_many_symbolic_link_levels)
      throw ConfigError(fmt::format("{}: ore card '{}' is a loop of symbolic links; expected an ore card (a YAML file)",
                                    d.where("ore.card"), t.string()));
    if (fs::exists(t, ec))
      throw ConfigError(fmt::format("{}: ore card '{}' is {}; expected an ore card (a YAML file)", d.where("ore.card"),
                                    t.string(), fs::is_directory(t, ec) ? "a directory" : "not a regular file"));
  }
  std::string where;
  for (const auto& t : tried) where += "\n  " + t.string();
  std::string have;
  const fs::path mats = project_dir / "liggghts_inputs" / "materials";
  if (fs::is_directory(mats))
    for (const auto& e : fs::directory_iterator(mats))
      if (e.path().extension() == ".yaml") have += " " + e.path().stem().string();
  throw ConfigError(fmt::format("{}: ore card '{}' not found; looked in:{}\nbundled ore cards:{}", d.where("ore.card"),
                                p.string(), where, have.empty() ? " (none)" : have));
}

}  // namespace

std::optional<int> stage_np(const Document& d, const std::string& stage, bool default_counts) {
  const std::string key = "resources." + stage + ".np";
  if (!case_schema().find(key)) return std::nullopt;  // a stage without MPI engines
  if (default_counts ? !d.has(key) : d.line(key) == 0) return std::nullopt;
  return static_cast<int>(d.integer(key));
}

nlohmann::json outliers(const CaseConfig& c) {
  nlohmann::json all = c.doc.outliers();
  for (const auto& o : c.ore.outliers()) all.push_back(o);
  return all;
}

CaseConfig load_case(const fs::path& file, const fs::path& project_dir,
                     const std::vector<std::pair<std::string, std::string>>& overrides) {
  CaseConfig c;
  const std::string text = read_regular_file(file, "case file");  // first: names a missing file or a link loop
  c.file = fs::weakly_canonical(file);
  c.project_dir = project_dir;
  c.doc = Document::parse(text, file.string(), case_schema(), overrides);
  check_case(c.doc);
  check_name(c.doc);
  c.feed = read_feed(c.doc);
  c.name = c.doc.str("name");
  c.ore_file = resolve_ore(c.doc, file, project_dir);
  c.ore = Document::load(c.ore_file, ore_schema());
  check_ore(c.ore);
  // The direct tension test's target (lump/material.h, tensile_target).
  if (c.doc.str("calibrate.tensile_test") == "direct" && !c.ore.has("direct_tensile_strength") &&
      !c.ore.has("rock_class"))
    throw ConfigError(fmt::format(
        "{}: calibrate.tensile_test is direct but the ore card {} gives neither "
        "direct_tensile_strength "
        "[Pa] nor rock_class (sedimentary, igneous or metamorphic, to convert its Brazilian "
        "tensile_strength: Perras & Diederichs 2014): add one to the card, or set "
        "calibrate.tensile_test: "
        "brazilian",
        c.doc.where("calibrate.tensile_test"), c.ore_file.string()));
  return c;
}

}  // namespace mill::config
