// Fragments by union-find over intact bonds; see fragments.h.
#include "postprocess/fragments.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace mill::post {
namespace {

// Disjoint sets over 0..n-1 with path halving and union by size.
class DisjointSets {
 public:
  // Makes n singleton sets.
  explicit DisjointSets(std::size_t n) : parent_(n), size_(n, 1) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }

  // Representative of the set holding a.
  std::size_t Find(std::size_t a) {
    while (parent_[a] != a) {
      parent_[a] = parent_[parent_[a]];
      a = parent_[a];
    }
    return a;
  }

  // Joins the sets holding a and b.
  void Unite(std::size_t a, std::size_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<std::size_t> parent_;
  std::vector<std::size_t> size_;
};

}  // namespace

// Equal-volume sphere diameter of `mass_kg` of solid ore.
double EquivalentDiameter(double mass_kg, double density_kg_m3) {
  if (!(density_kg_m3 > 0.0)) {
    throw PostError(fmt::format("ore density must be > 0 kg/m3, got {}", density_kg_m3));
  }
  return std::cbrt(6.0 * mass_kg / (kPi * density_kg_m3));
}

// Connected components of the element graph, heaviest first.
std::vector<Fragment> FindFragments(const std::vector<Element>& elements,
                                    const std::vector<Bond>& bonds, double density_kg_m3,
                                    const std::string& bond_source) {
  if (!(density_kg_m3 > 0.0)) {
    throw PostError(fmt::format("ore density must be > 0 kg/m3, got {}", density_kg_m3));
  }
  std::unordered_map<long long, std::size_t> index;
  index.reserve(elements.size() * 2);
  for (std::size_t k = 0; k < elements.size(); ++k) {
    if (!index.emplace(elements[k].id, k).second) {
      throw PostError(fmt::format("element id {} appears twice in the dump", elements[k].id));
    }
  }
  auto lookup = [&](long long id, std::size_t bond_no) {
    auto it = index.find(id);
    if (it == index.end()) {
      throw PostError(fmt::format(
          "{}: bond {} names atom id {}, which is not in the dump (is the bond file from the "
          "same run and step as the dump?)",
          bond_source, bond_no + 1, id));
    }
    return it->second;
  };
  DisjointSets sets(elements.size());
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    sets.Unite(lookup(bonds[b].i, b), lookup(bonds[b].j, b));
  }

  std::unordered_map<std::size_t, std::size_t> fragment_of_root;
  std::vector<Fragment> fragments;
  std::vector<std::array<double, 3>> momentum;
  for (std::size_t k = 0; k < elements.size(); ++k) {
    const std::size_t root = sets.Find(k);
    auto [it, fresh] = fragment_of_root.emplace(root, fragments.size());
    if (fresh) {
      fragments.emplace_back();
      momentum.push_back({0.0, 0.0, 0.0});
    }
    Fragment& f = fragments[it->second];
    const Element& e = elements[k];
    f.ids.push_back(e.id);
    f.mass += e.mass;
    for (int c = 0; c < 3; ++c) momentum[it->second][c] += e.mass * e.v[c];
  }
  for (std::size_t f = 0; f < fragments.size(); ++f) {
    Fragment& frag = fragments[f];
    std::sort(frag.ids.begin(), frag.ids.end());
    frag.diameter = EquivalentDiameter(frag.mass, density_kg_m3);
    for (int c = 0; c < 3; ++c) {
      frag.velocity[c] = frag.mass > 0.0 ? momentum[f][c] / frag.mass : 0.0;
    }
  }
  std::sort(fragments.begin(), fragments.end(), [](const Fragment& a, const Fragment& b) {
    if (a.mass != b.mass) return a.mass > b.mass;
    return a.ids.front() < b.ids.front();
  });
  return fragments;
}

}  // namespace mill::post
