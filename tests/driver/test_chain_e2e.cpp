// Stage 1 end to end with real engines: the tiny OpenFOAM case, its sampled
// field, and a handful of lumps tracked through it; then the report.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Run in `cwd`, so that the default run folder (runs/<case>) is relative,
// as it is for a user who types the README's command.
int orchestrate(const fs::path& cwd, const std::string& args, const fs::path& log) {
  const std::string cmd = "cd '" + cwd.string() + "' && MILL_LIGGGHTS='" + std::string(LIGGGHTS_MILL_EXE) + "' '" + ORCHESTRATE_EXE + "' " + args +
                          " > '" + log.string() + "' 2>&1";
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(Stage1Chain, FlowSampleTransportOnTheTinyMesh) {
  const fs::path dir = fs::temp_directory_path() / ("mill_chain_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string base = "--case " + std::string(MILL_TEST_DATA) + "/tiny_chain.yaml";
  for (const char* stage : {"flow", "sample", "transport", "report"}) {
    const fs::path log = dir / (std::string(stage) + ".log");
    ASSERT_EQ(orchestrate(dir, base + " --stage " + stage, log), 0) << stage << ":\n" << slurp(log);
  }
  const fs::path run = dir / "runs" / "tiny_chain";
  // The transport stage read the sampled CFD field, not a synthetic one.
  EXPECT_TRUE(fs::exists(run / "sample/rpm2000/field.h5"));
  const auto s = nlohmann::json::parse(slurp(run / "transport/rpm2000/summary.json"));
  EXPECT_EQ(s.at("n_particles").get<int>(), 6);
  EXPECT_TRUE(fs::exists(run / "transport/rpm2000/impacts.csv"));
  EXPECT_TRUE(fs::exists(run / "transport/rpm2000/plots/trajectories.png"));
  const std::string html = slurp(run / "report/index.html");
  EXPECT_NE(html.find("Stage 1b: ore lumps through the mill"), std::string::npos);
  EXPECT_NE(html.find("sample/rpm2000/"), std::string::npos);
}

}  // namespace
