// The bad-input corpus (tests/bad_input/manifest.txt): every case is one
// orchestrate command that must end with its exit status and a message that
// holds its fragment, with no raw library text and no runaway numbers.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

struct Case {
  std::string name;
  int exit_status = 0;
  std::string fragment;
  std::string setup;
  std::string args;
  int line = 0;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size())) s.replace(p, from.size(), to);
  return s;
}

// The manifest's cases; a malformed line becomes a case that fails, naming it.
std::vector<Case> load_manifest() {
  std::vector<Case> cases;
  std::ifstream in(std::string(MILL_BAD_INPUT_DIR) + "/manifest.txt");
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    std::vector<std::string> f;
    size_t start = 0;
    for (int i = 0; i < 4; ++i) {
      const size_t bar = line.find('|', start);
      if (bar == std::string::npos) break;
      f.push_back(trim(line.substr(start, bar - start)));
      start = bar + 1;
    }
    f.push_back(trim(line.substr(start)));
    Case c;
    c.line = n;
    if (f.size() != 5) {
      c.name = "malformed_line_" + std::to_string(n);
      c.exit_status = -1000;
    } else {
      c.name = f[0];
      c.exit_status = std::atoi(f[1].c_str());
      c.fragment = f[2];
      c.setup = f[3];
      c.args = f[4];
    }
    cases.push_back(c);
  }
  return cases;
}

std::string run(const std::string& cmd, int& status) {
  FILE* p = popen(cmd.c_str(), "r");
  std::string text;
  std::array<char, 4096> buf{};
  size_t k;
  while ((k = fread(buf.data(), 1, buf.size(), p)) > 0) text.append(buf.data(), k);
  const int st = pclose(p);
  status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return text;
}

class BadInput : public ::testing::TestWithParam<Case> {};

TEST_P(BadInput, ExitStatusAndMessage) {
  const Case& c = GetParam();
  ASSERT_NE(c.exit_status, -1000) << "manifest.txt:" << c.line << ": expected 5 fields separated by '|'";
  // Removed, with its parent folder once empty, when the case passes.
  const mill::test::TempDir tmp(fs::path("mill_bad_input_" + std::to_string(getpid())) / c.name);
  auto subst = [&](const std::string& s) {
    return replace_all(replace_all(replace_all(s, "@DATA@", MILL_BAD_INPUT_DIR), "@TMP@", tmp.string()), "@PROJECT@",
                       MILL_PROJECT_DIR);
  };
  const std::string args = subst(c.args);
  std::string cmd = "cd '" + tmp.string() + "' && ";
  if (!c.setup.empty()) cmd += "{ " + subst(c.setup) + " ; } && ";
  // `timeout`: a command that hangs (e.g. reading a FIFO) fails the case.
  cmd += "timeout -k 5 30 '" + std::string(ORCHESTRATE_EXE) + "' " + args + " 2>&1";
  int status = 0;
  const std::string text = run(cmd, status);
  EXPECT_NE(status, 124) << c.name << ": orchestrate hung (killed after 30 s)";
  EXPECT_EQ(status, c.exit_status) << "manifest.txt:" << c.line << " " << c.name << "\n" << text;
  EXPECT_NE(text.find(subst(c.fragment)), std::string::npos)
      << "manifest.txt:" << c.line << " " << c.name << ": missing '" << c.fragment << "' in:\n"
      << text;
  for (const char* raw : {"filesystem error", "terminate called", "what():", "yaml-cpp:"})
    EXPECT_EQ(text.find(raw), std::string::npos) << c.name << ": raw library text '" << raw << "' in:\n" << text;
  // A number of 20 or more digits that the user did not type is a range or
  // a value printed unreadably (e.g. a CLI bound of 1.8e308 written out).
  const std::regex long_number("[0-9]{20,}");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), long_number); it != std::sregex_iterator(); ++it)
    EXPECT_NE(args.find(it->str()), std::string::npos)
        << c.name << ": unreadable number " << it->str() << " in:\n"
        << text;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(load_manifest()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

TEST(BadInputCorpus, HasAtLeastFortyCases) {
  const auto cases = load_manifest();
  EXPECT_GE(cases.size(), 40u);
  std::set<std::string> names;
  for (const auto& c : cases) EXPECT_TRUE(names.insert(c.name).second) << "two cases named " << c.name;
}

}  // namespace
