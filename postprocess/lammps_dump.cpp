// Dump and bond-file readers; see lammps_dump.h.
#include "postprocess/lammps_dump.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

namespace mill::post {
namespace {

// Splits a line on whitespace.
std::vector<std::string> Split(const std::string& line) {
  std::istringstream ss(line);
  std::vector<std::string> out;
  std::string tok;
  while (ss >> tok) out.push_back(tok);
  return out;
}

// Parses a whole token as a double, or throws naming where it came from.
double ToDouble(const std::string& tok, const std::string& where, const std::string& what) {
  try {
    std::size_t used = 0;
    const double v = std::stod(tok, &used);
    if (used == tok.size()) return v;
  } catch (const std::exception&) {
  }
  throw PostError(fmt::format("{}: {}: expected a number, got '{}'", where, what, tok));
}

// Parses a whole token as an integer, or throws naming where it came from.
long long ToInt(const std::string& tok, const std::string& where, const std::string& what) {
  try {
    std::size_t used = 0;
    const long long v = std::stoll(tok, &used);
    if (used == tok.size()) return v;
  } catch (const std::exception&) {
  }
  throw PostError(fmt::format("{}: {}: expected an integer, got '{}'", where, what, tok));
}

// Reads the next line into `line`, counting lines; false at end of input.
bool NextLine(std::istream& in, std::string& line, long long& line_no) {
  if (!std::getline(in, line)) return false;
  ++line_no;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

// Column positions of the ATOMS header, found by name.
struct Columns {
  int id = -1, type = -1, radius = -1, mass = -1;
  std::array<int, 3> x{-1, -1, -1}, v{-1, -1, -1};
  std::size_t count = 0;
};

// Locates the needed columns in "ITEM: ATOMS name name ..."; throws if one is missing.
Columns LocateColumns(const std::vector<std::string>& words, const std::string& where) {
  std::map<std::string, int> at;
  for (std::size_t k = 2; k < words.size(); ++k) at.emplace(words[k], static_cast<int>(k - 2));
  auto find = [&](std::initializer_list<const char*> names) {
    for (const char* n : names) {
      auto it = at.find(n);
      if (it != at.end()) return it->second;
    }
    return -1;
  };
  Columns c;
  c.count = words.size() - 2;
  c.id = find({"id"});
  c.type = find({"type"});
  c.radius = find({"radius"});
  c.mass = find({"mass"});
  c.x = {find({"x", "xu"}), find({"y", "yu"}), find({"z", "zu"})};
  c.v = {find({"vx"}), find({"vy"}), find({"vz"})};
  const std::pair<const char*, int> required[] = {
      {"id", c.id}, {"radius", c.radius}, {"vx", c.v[0]}, {"vy", c.v[1]}, {"vz", c.v[2]}};
  for (const auto& [name, pos] : required) {
    if (pos < 0) {
      throw PostError(fmt::format(
          "{}: ITEM: ATOMS has no '{}' column (needed: id radius vx vy vz; add it to the "
          "`dump custom` line)",
          where, name));
    }
  }
  return c;
}

}  // namespace

// Last snapshot of a dump file on disk.
DumpSnapshot ReadDumpLastSnapshot(const std::string& path, double density_kg_m3) {
  std::ifstream in(path);
  if (!in) throw PostError(fmt::format("{}: cannot open dump file", path));
  return ParseDumpLastSnapshot(in, path, density_kg_m3);
}

// Last snapshot of a dump stream; each snapshot is parsed in full so that a
// malformed earlier one is reported too.
DumpSnapshot ParseDumpLastSnapshot(std::istream& in, const std::string& label,
                                   double density_kg_m3) {
  DumpSnapshot snap;
  std::optional<long long> n_atoms;
  std::string line;
  long long line_no = 0;
  auto where = [&]() { return fmt::format("{}:{}", label, line_no); };
  auto need_line = [&](const char* what) {
    if (!NextLine(in, line, line_no)) {
      throw PostError(fmt::format("{}:{}: file ends where {} was expected (truncated dump?)", label,
                                  line_no, what));
    }
  };
  while (NextLine(in, line, line_no)) {
    const auto words = Split(line);
    if (words.empty()) continue;
    if (words[0] != "ITEM:" || words.size() < 2) {
      throw PostError(fmt::format("{}: expected an 'ITEM:' line, got '{}'", where(), line));
    }
    const std::string& item = words[1];
    if (item == "TIMESTEP") {
      need_line("the timestep");
      const auto w = Split(line);
      if (w.empty()) throw PostError(fmt::format("{}: empty TIMESTEP line", where()));
      DumpSnapshot next;
      next.timestep = ToInt(w[0], where(), "TIMESTEP");
      next.n_snapshots = snap.n_snapshots + 1;
      snap = std::move(next);
      n_atoms.reset();
    } else if (item == "NUMBER") {
      need_line("the number of atoms");
      const auto w = Split(line);
      if (w.empty()) throw PostError(fmt::format("{}: empty NUMBER OF ATOMS line", where()));
      n_atoms = ToInt(w[0], where(), "NUMBER OF ATOMS");
      if (*n_atoms < 0) {
        throw PostError(fmt::format("{}: NUMBER OF ATOMS must be >= 0, got {}", where(), *n_atoms));
      }
    } else if (item == "BOX") {
      for (int d = 0; d < 3; ++d) {
        need_line("a box bound");
        const auto w = Split(line);
        if (w.size() < 2) throw PostError(fmt::format("{}: box bound needs lo hi", where()));
        snap.box[2 * d] = ToDouble(w[0], where(), "box lo");
        snap.box[2 * d + 1] = ToDouble(w[1], where(), "box hi");
      }
    } else if (item == "ATOMS") {
      if (!n_atoms) {
        throw PostError(fmt::format("{}: ITEM: ATOMS before ITEM: NUMBER OF ATOMS", where()));
      }
      const Columns c = LocateColumns(words, where());
      snap.mass_from_density = c.mass < 0;
      if (snap.mass_from_density && !(density_kg_m3 > 0.0)) {
        throw PostError(fmt::format(
            "{}: the dump has no 'mass' column, so an ore density > 0 kg/m3 is needed, got {}",
            where(), density_kg_m3));
      }
      snap.elements.clear();
      snap.elements.reserve(static_cast<std::size_t>(*n_atoms));
      for (long long a = 0; a < *n_atoms; ++a) {
        need_line("an atom line");
        const auto w = Split(line);
        if (w.size() != c.count) {
          throw PostError(fmt::format("{}: atom line has {} values, the ATOMS header names {}",
                                      where(), w.size(), c.count));
        }
        Element e;
        e.id = ToInt(w[c.id], where(), "id");
        if (c.type >= 0) e.type = static_cast<int>(ToInt(w[c.type], where(), "type"));
        e.radius = ToDouble(w[c.radius], where(), "radius");
        if (!(e.radius > 0.0)) {
          throw PostError(
              fmt::format("{}: radius of atom {} must be > 0 m, got {}", where(), e.id, e.radius));
        }
        for (int d = 0; d < 3; ++d) {
          if (c.x[d] >= 0) e.x[d] = ToDouble(w[c.x[d]], where(), "position");
          e.v[d] = ToDouble(w[c.v[d]], where(), "velocity");
        }
        e.mass = c.mass >= 0 ? ToDouble(w[c.mass], where(), "mass")
                             : SphereMass(e.radius, density_kg_m3);
        if (!(e.mass > 0.0)) {
          throw PostError(
              fmt::format("{}: mass of atom {} must be > 0 kg, got {}", where(), e.id, e.mass));
        }
        snap.elements.push_back(e);
      }
    } else {
      throw PostError(fmt::format("{}: unknown item 'ITEM: {}'", where(), item));
    }
  }
  if (snap.n_snapshots == 0) {
    throw PostError(fmt::format("{}: no 'ITEM: TIMESTEP' found (empty or not a dump file)", label));
  }
  if (!n_atoms || snap.elements.size() != static_cast<std::size_t>(*n_atoms)) {
    throw PostError(
        fmt::format("{}: last snapshot (step {}) has no ATOMS section (truncated dump?)", label,
                    snap.timestep));
  }
  return snap;
}

// Intact bonds from a bond file on disk.
std::vector<Bond> ReadIntactBonds(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PostError(fmt::format("{}: cannot open bond file", path));
  return ParseIntactBonds(in, path);
}

// Intact bonds from a stream of `tag_i tag_j` lines.
std::vector<Bond> ParseIntactBonds(std::istream& in, const std::string& label) {
  std::vector<Bond> bonds;
  std::string line;
  long long line_no = 0;
  while (NextLine(in, line, line_no)) {
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto w = Split(line);
    const std::string where = fmt::format("{}:{}", label, line_no);
    if (w.size() != 2) {
      throw PostError(
          fmt::format("{}: expected 'tag_i tag_j', got {} values in '{}'", where, w.size(), line));
    }
    Bond b{ToInt(w[0], where, "tag_i"), ToInt(w[1], where, "tag_j")};
    if (b.i == b.j) throw PostError(fmt::format("{}: bond joins atom {} to itself", where, b.i));
    bonds.push_back(b);
  }
  return bonds;
}

}  // namespace mill::post
