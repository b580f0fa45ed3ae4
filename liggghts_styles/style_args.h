// Keyword values of the project's fix styles: `fix ID group STYLE key value ...`.
//
// StyleArgs turns the text given for a keyword into a number or fails through
// LIGGGHTS's Error (error->all, so every rank stops) with a message that names
// the style, the keyword, what was expected and what was given, e.g.
//   fix bond/breakable: modulus expects a number, got '2x10'
//   fix bond/breakable: modulus must be > 0 Pa, got 0
//   fix bond/breakable: max_bonds must be an integer in [1, 64], got 0
#ifndef MILL_STYLE_ARGS_H
#define MILL_STYLE_ARGS_H

#include <string>

namespace LAMMPS_NS {
class Error;
}

namespace mill {

class StyleArgs {
 public:
  // Parses for fix style `style` (e.g. "bond/breakable"), failing through error.
  StyleArgs(LAMMPS_NS::Error *error, const char *style) : error_(error), style_(style) {}

  // A finite real number given for keyword key.
  double real(const char *key, const char *text) const;
  // A real number > 0 for key; unit ("Pa", or "" for none) is named on failure.
  double positive(const char *key, const char *text, const char *unit = "") const;
  // A whole number in [lo, hi] for key (written as a real, so "1e1" is 10).
  int integer(const char *key, const char *text, int lo, int hi) const;

 private:
  // Stops the run with "fix STYLE: msg".
  void fail(const std::string &msg) const;

  LAMMPS_NS::Error *error_;
  std::string style_;
};

}  // namespace mill

#endif
