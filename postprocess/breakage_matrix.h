// The breakage matrix of the population balance from the pieces of lumps
// run in the mill: the pieces of each lump binned on the balance's size
// classes into the column of the lump's class (mass-weighted over the
// lumps), the classes that were not run filled by scaling a measured column
// in relative size (a normalised breakage function, Austin, Klimpel & Luckie
// 1984), the finest class (0, ..., 0, 1). Called by the breakage stage once
// per rotor speed; docs/population_balance.md, "Breakage matrix from the
// in-mill runs".
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "postprocess/population_balance.h"

namespace mill::post {

// The pieces of one lump: size (mm) and mass (kg) per piece.
struct LumpPieces {
  std::vector<double> size_mm;
  std::vector<double> mass_kg;
};

// The mass of one lump's pieces per class (coarsest first, the same unit as
// mass_kg), for a lump of class j: a piece goes to the class whose [lower,
// upper) holds its size (SizeFractionMass of distributions.h); a piece at or
// above class j's upper edge counts in class j (nothing gets coarser than
// the lump's class). Throws PostError on bad pieces or j out of range.
std::vector<double> BinPieces(const SizeClasses& classes, std::size_t j, const LumpPieces& pieces);

// Column j of the breakage matrix from the pieces of lumps of class j: the
// binned masses summed over the lumps, over their total mass (the lumps'
// mean weighted by their mass). Sums to 1. Throws PostError when there is
// no lump or no mass.
std::vector<double> MeasuredBreakageColumn(const SizeClasses& classes, std::size_t j,
                                           const std::vector<LumpPieces>& lumps);

// Column j scaled from the measured column of class m (Austin et al. 1984:
// a normalised breakage function, b_ij depends on x_i / x_j only). The
// measured column is read as the passing P(s) at relative sizes s = sieve /
// x_m (x: RepresentativeSize), linear in log(s) between its sieves, 1 at and
// above its own top sieve and held at its finest sieve's value below it (the
// pan's mass stays in the pan); class j's column takes P(sieve / x_j) at its
// sieves. Sums to 1 exactly; on a geometric sieve series it is the measured
// column shifted by j - m classes. Throws PostError on bad input.
std::vector<double> ScaledBreakageColumn(const SizeClasses& classes, std::size_t m,
                                         const std::vector<double>& column_m, std::size_t j);

// Where a column of an assembled matrix came from.
struct ColumnOrigin {
  std::string kind;      // "measured", "scaled" or "finest"
  std::size_t from = 0;  // the measured class it was scaled from ("scaled")
};

struct AssembledMatrix {
  BreakageMatrix b;                  // validated (ValidateBreakageMatrix)
  std::vector<ColumnOrigin> origin;  // per column
};

// The measured class nearest to class j in log(representative size)
// (RepresentativeSize), the coarser of two equally near (within 1e-12 in
// log size); j itself when it is measured. The rule by which a class without
// lumps borrows from a measured one: its scaled column here, its beater work
// per kg in circuit_energy.h. Throws PostError when `measured` is empty or
// an index is out of range.
std::size_t NearestMeasuredClass(const SizeClasses& classes, std::size_t j,
                                 const std::vector<std::size_t>& measured);

// The whole matrix: the measured columns as given, the finest class
// (0, ..., 0, 1), every other class scaled from the measured class nearest
// in log(representative size) (the coarser of two equally near). Throws
// PostError when nothing is measured or a measured column is bad.
AssembledMatrix AssembleBreakageMatrix(const SizeClasses& classes,
                                       const std::map<std::size_t, std::vector<double>>& measured);

// The class (index, coarsest first) whose [lower, upper) holds size_mm, or
// classes.size() when size_mm is at or above the top sieve.
std::size_t ClassOfSize(const SizeClasses& classes, double size_mm);

}  // namespace mill::post
