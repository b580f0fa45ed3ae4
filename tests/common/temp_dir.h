// Scratch folders and files of the tests under the temp dir
// (std::filesystem::temp_directory_path(): $TMPDIR or /tmp). Each is removed
// when the test that made it passes and kept, its path printed, when the test
// fails, so that a failure can be looked into; with MILL_KEEP_TEST_DIRS set
// every one is kept.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iterator>
#include <ostream>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

namespace mill::test {

// Whether what runs now has failed: the running test; between the tests of
// a suite (SetUpTestSuite, TearDownTestSuite) any test of the suite or its
// set-up; outside a suite, any test of the program.
inline bool failed_so_far() {
  const ::testing::UnitTest* u = ::testing::UnitTest::GetInstance();
  if (u->current_test_info() != nullptr) return ::testing::Test::HasFailure();
  if (const ::testing::TestSuite* s = u->current_test_suite()) return s->Failed();
  return u->Failed();
}

// MILL_KEEP_TEST_DIRS is set: keep every scratch path.
inline bool keep_all_requested() { return std::getenv("MILL_KEEP_TEST_DIRS") != nullptr; }

// The end of scratch path `p`: kept and printed after a failure (`failed`) or
// with MILL_KEEP_TEST_DIRS; otherwise removed with all it holds, and then
// each of its `parents` folders above it that is left empty. Never throws.
//
// A removal that fails is retried for up to 5 s: files may still vanish in
// there just after a run (Open MPI tidies a singleton run's session folder
// after the run has returned; remove_all then fails on a vanished entry).
inline void remove_unless_failed(const std::filesystem::path& p, bool failed, int parents = 0) {
  std::error_code ec;
  if (failed || keep_all_requested()) {
    if (std::filesystem::exists(p, ec))
      std::fprintf(stderr, "kept %s (%s)\n", p.c_str(),
                   failed ? "the test failed" : "MILL_KEEP_TEST_DIRS is set");
    return;
  }
  for (int tries = 1; std::filesystem::remove_all(p, ec) == static_cast<std::uintmax_t>(-1);
       ++tries) {
    if (tries == 50) {
      std::fprintf(stderr, "could not remove %s: %s\n", p.c_str(), ec.message().c_str());
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::filesystem::path up = p.parent_path();
  for (int k = 0; k < parents && std::filesystem::remove(up, ec); ++k) up = up.parent_path();
}

// A path under the temp dir that a test owns: temp_directory_path() / `name`
// (relative; its folders, as in "run_<pid>/case", are made by TempDir). What
// an earlier run left there is removed first. When the object goes out of
// scope in the process that made it (not in a forked child), the path is
// removed if the test passed, with the folders of `name` above it once they
// are empty, and kept, its path printed, if the test failed or an exception
// is leaving the scope. A move hands the path on.
//
// It stands for its path (converts to `const std::filesystem::path&`; `/`,
// string(), path()); on a temporary, which would remove the path at once,
// these do not compile: keep it in a variable for as long as the path is
// used, e.g. until the child processes that write there have ended.
class TempPath {
 public:
  explicit TempPath(const std::filesystem::path& name)
      : path_(std::filesystem::temp_directory_path() / name),
        parents_(static_cast<int>(std::distance(name.begin(), name.end())) - 1) {
    std::filesystem::remove_all(path_);
  }
  TempPath(TempPath&& o) noexcept
      : path_(std::move(o.path_)),
        parents_(o.parents_),
        owner_(o.owner_),
        exceptions_(o.exceptions_),
        kept_(o.kept_) {
    o.owner_ = -1;  // the moved-from object removes nothing
  }
  TempPath(const TempPath&) = delete;
  TempPath& operator=(const TempPath&) = delete;
  TempPath& operator=(TempPath&&) = delete;
  ~TempPath() {
    if (getpid() != owner_ || kept_) return;
    remove_unless_failed(path_, std::uncaught_exceptions() > exceptions_ || failed_so_far(),
                         parents_);
  }

  // Leaves the path in place whatever the outcome (a run a later test reads).
  void keep() { kept_ = true; }

  const std::filesystem::path& path() const& { return path_; }
  const std::filesystem::path& path() const&& = delete;
  operator const std::filesystem::path&() const& { return path_; }
  operator const std::filesystem::path&() const&& = delete;
  std::filesystem::path operator/(const std::filesystem::path& p) const& { return path_ / p; }
  std::filesystem::path operator/(const std::filesystem::path& p) const&& = delete;
  std::string string() const& { return path_.string(); }
  std::string string() const&& = delete;
  friend std::ostream& operator<<(std::ostream& o, const TempPath& t) { return o << t.path_; }

 private:
  std::filesystem::path path_;
  int parents_;
  pid_t owner_ = getpid();
  int exceptions_ = std::uncaught_exceptions();
  bool kept_ = false;
};

// A TempPath that is a fresh, empty folder.
class TempDir : public TempPath {
 public:
  explicit TempDir(const std::filesystem::path& name) : TempPath(name) {
    std::filesystem::create_directories(path());
  }
};

}  // namespace mill::test
