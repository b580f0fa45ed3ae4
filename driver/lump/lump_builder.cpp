// Packing and caching of the breakage lump.
#include "lump/lump_builder.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "jobs/job_store.h"
#include "progress.h"

namespace mill {
namespace fs = std::filesystem;

LumpSpec lump_spec(const config::CaseConfig& cfg) {
  const auto& d = cfg.doc;
  return {d.integer("lump.n_elements"), d.real("lump.diameter"),       d.real("lump.radius_spread"),
          d.integer("lump.seed"),       d.real("lump.bond_gap"),       d.integer("lump.max_bonds"),
          cfg.ore.real("density"),      cfg.ore.real("poisson_ratio"), ""};
}

namespace {

// Exclusive lock on a file for the lifetime of the object.
class FileLock {
 public:
  explicit FileLock(const fs::path& p) {
    fs::create_directories(p.parent_path());
    fd_ = open(p.c_str(), O_RDWR | O_CREAT, 0644);
    if (fd_ < 0 || flock(fd_, LOCK_EX) != 0) throw std::runtime_error("cannot lock " + p.string());
  }
  ~FileLock() {
    if (fd_ >= 0) {
      flock(fd_, LOCK_UN);
      close(fd_);
    }
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};

// The ball of packing `packing`: the lump's element count and size, seed
// stream 2 (lump.seed + packing) (packing_seeds).
BallPacking lump_packing(const LumpSpec& s, int packing) {
  BallPacking b;
  b.n_elements = s.n_elements;
  b.mean_radius = target_mean_radius(s.n_elements, s.diameter, s.spread);
  b.spread = s.spread;
  b.density = s.density;
  b.nu = s.nu;
  b.bond_gap = s.bond_gap;
  b.max_bonds = s.max_bonds;
  b.seed_stream = 2 * (s.seed + packing);
  return b;
}

// Packs the lump into <dir>/build and publishes lump.data, lump_info.txt and
// build.log in <dir>.
LumpInfo build_lump(const PackingEnv& env, const LumpSpec& s, int packing, const fs::path& dir,
                    const std::string& label) {
  const fs::path tmp = dir / "build";
  LumpInfo li =
      pack_ball(env, lump_packing(s, packing), tmp, "lump", "breakage/lumps/" + label, label);
  // Publish: data and info renamed into place, then STATUS done.
  fs::rename(tmp / "lump.data", dir / "lump.data");
  fs::rename(tmp / "lump_info.txt", dir / "lump_info.txt");
  fs::rename(tmp / "liggghts.log", dir / "build.log");
  fs::remove_all(tmp);
  return li;
}

}  // namespace

LumpInfo ensure_lump(const PackingEnv& env, const fs::path& cache_dir, const LumpSpec& s,
                     int packing, const std::string& requester) {
  const std::string label = fmt::format("n{}{}_p{}", s.n_elements, s.tag, packing);
  nlohmann::json in = {{"n_elements", s.n_elements}, {"diameter", s.diameter},
                       {"spread", s.spread},         {"seed", s.seed + packing},
                       {"bond_gap", s.bond_gap},     {"max_bonds", s.max_bonds},
                       {"density", s.density},       {"nu", s.nu},
                       {"deck_version", 2}};
  jobs::JobStore store(cache_dir);
  FileLock lock(cache_dir / (label + ".lock"));
  const fs::path dir = store.job_dir(label);
  if (store.decide(label, in, false).decision == jobs::Decision::Skip) {
    LumpInfo li = parse_lump_info(dir / "lump_info.txt");
    li.data = dir / "lump.data";
    li.label = label;
    return li;
  }
  store.mark_running(label, in);
  env.progress.info(fmt::format("[breakage] {}: building lump {} ({} elements, {:g} mm)", requester,
                                label, s.n_elements, s.diameter * 1e3));
  try {
    LumpInfo li = build_lump(env, s, packing, dir, label);
    store.mark_done(label);
    li.data = dir / "lump.data";
    li.label = label;
    env.progress.info(fmt::format(
        "[breakage] lump {}: {} elements, outer diameter {:.1f} mm (asked {:.1f} mm), mean element "
        "radius {:.3f} mm, solid fraction of the bounding sphere {:.2f}, {} bonds, mean "
        "coordination {:.2f}",
        label, li.elements, 2e3 * li.outer_radius, s.diameter * 1e3, li.mean_radius * 1e3,
        li.solid_fraction, li.bonds, li.coordination));
    return li;
  } catch (const std::exception& e) {
    store.mark_failed(label, e.what());
    throw;
  }
}

}  // namespace mill
