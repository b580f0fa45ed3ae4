// Keyword values of the project's fix styles; see style_args.h.
#include "style_args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "error.h"

namespace mill {

// Stops the run on every rank with the style's name in front of msg.
void StyleArgs::fail(const std::string &msg) const {
  const std::string m = "fix " + style_ + ": " + msg;
  error_->all(FLERR, m.c_str());
}

// Parses a number given for keyword key, or fails with a message naming both.
double StyleArgs::real(const char *key, const char *text) const {
  char *end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    fail(std::string(key) + " expects a number, got '" + text + "'");
  return v;
}

// Parses a number for key and checks that it is > 0.
double StyleArgs::positive(const char *key, const char *text, const char *unit) const {
  const double v = real(key, text);
  if (!(v > 0.0))
    fail(std::string(key) + " must be > 0" + (*unit ? std::string(" ") + unit : std::string()) +
         ", got " + text);
  return v;
}

// Parses a number for key and checks that it is a whole number in [lo, hi].
int StyleArgs::integer(const char *key, const char *text, int lo, int hi) const {
  const double v = real(key, text);
  if (!(v >= lo && v <= hi && v == std::floor(v)))
    fail(std::string(key) + " must be an integer in [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "], got " + text);
  return static_cast<int>(v);
}

}  // namespace mill
