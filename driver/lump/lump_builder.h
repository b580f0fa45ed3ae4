// The bonded lump of the breakage stage: packed once per (lump keys, packing)
// by pack_ball, cached in a job store (the breakage stage keeps it under
// <run>/breakage/lumps/) and shared by every impact of a campaign (a file
// lock serialises builders).
#pragma once

#include <filesystem>
#include <string>

#include "config/case_config.h"
#include "lump/packing.h"

namespace mill {

// What decides a lump's packings (their job inputs).
struct LumpSpec {
  long n_elements;
  double diameter;
  double spread;
  long seed;
  double bond_gap;
  long max_bonds;
  double density;
  double nu;
  // Put in the cache label ("n40_d18.93mm_p0") of a lump that is not
  // lump.diameter's (a feed class's); "" for lump.diameter's ("n40_p0").
  std::string tag;
};

LumpSpec lump_spec(const config::CaseConfig& cfg);

// Build (or reuse) packing `packing` of the lump in the job store at
// `cache_dir`; returns its description. `requester` names the job that asked,
// in the progress.
LumpInfo ensure_lump(const PackingEnv& env, const std::filesystem::path& cache_dir,
                     const LumpSpec& spec, int packing, const std::string& requester);

}  // namespace mill
