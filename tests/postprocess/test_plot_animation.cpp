// plot_animation.py on small hand-written frame dumps: the frames it reads
// (count, times, centroids), the GIF's frame count and that its frames
// differ; a missing, truncated or incomplete dump stops it with a message
// naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "temp_dir.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;
const std::string kPython = "/usr/bin/python3";
const std::string kScript = MILL_PLOT_ANIMATION_SCRIPT;

bool PythonHasPlotting() {
  const std::string cmd = kPython + " -c 'import matplotlib, numpy, PIL' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

std::string Slurp(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// An axis-aligned box [lo, hi] as an ASCII STL, normals outwards.
void WriteBox(const fs::path& f, std::array<double, 3> lo, std::array<double, 3> hi) {
  std::ofstream o(f);
  o << "solid box\n";
  auto p = [&](int i, int j, int k) {
    return std::array<double, 3>{i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2]};
  };
  // Each face as two triangles, counter-clockwise seen from outside.
  const int quads[6][4][3] = {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},   // -z
                              {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},   // +z
                              {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},   // -y
                              {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},   // +y
                              {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},   // -x
                              {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}};  // +x
  for (const auto& q : quads)
    for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      o << "  facet normal 0 0 0\n    outer loop\n";
      for (int v : tri) {
        const auto x = p(q[v][0], q[v][1], q[v][2]);
        o << "      vertex " << x[0] << " " << x[1] << " " << x[2] << "\n";
      }
      o << "    endloop\n  endfacet\n";
    }
  o << "endsolid box\n";
}

// One snapshot of `dump custom` with the deck's columns; elements i = 1..n
// at x = x0 + 0.01 i, y = y0, 6 - step / 100 intact bonds each.
std::string Snapshot(long step, double time, int n, double x0, double y0, int skip_rows = 0) {
  std::ostringstream o;
  o << "ITEM: TIMESTEP\n"
    << step << "\nITEM: NUMBER OF ATOMS\n"
    << n << "\nITEM: BOX BOUNDS mm mm mm\n-1 1\n-1 1\n-1 1\n"
    << "ITEM: ATOMS id type radius x y z f_bonds v_frame_time\n";
  for (int i = 1; i <= n - skip_rows; ++i)
    o << i << " 1 0.004 " << x0 + 0.01 * i << " " << y0 << " 0 " << 6 - step / 100 << " " << time
      << "\n";
  return o.str();
}

struct Outcome {
  int status;
  std::string err;
};

// Runs the script on `frames` with a 1 m box housing and a 0.2 m box flywheel.
Outcome Render(const fs::path& dir, const fs::path& frames) {
  WriteBox(dir / "housing.stl", {-0.5, 0.0, -0.1}, {0.5, 1.0, 0.1});
  WriteBox(dir / "flywheel.stl", {-0.1, 0.3, -0.05}, {0.1, 0.5, 0.05});
  const std::string cmd =
      kPython + " " + kScript + " --frames " + frames.string() + " --housing " +
      (dir / "housing.stl").string() + " --flywheel " + (dir / "flywheel.stl").string() +
      " --axis 0,0.4 --omega 100 --caption 'lump 7 at 1000 rpm' --out " +
      (dir / "animation").string() + " 2> " + (dir / "err.txt").string() + " >/dev/null";
  const int st = std::system(cmd.c_str());
  return {st, Slurp(dir / "err.txt")};
}

// An empty folder, removed when the test passes.
mill::test::TempDir Fresh(const std::string& name) {
  return mill::test::TempDir("mill_post_plot_animation_" + name + "_" + std::to_string(getpid()));
}

TEST(PlotAnimation, ReadsEveryFrameAndDrawsAGifWhoseFramesDiffer) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy/PIL";
  const auto dir = Fresh("ok");
  // Three snapshots; the three elements move from x = 0.02 to 0.32 and up 0.4 m.
  std::ofstream(dir / "frames.dump")
      << Snapshot(0, 0.0, 3, -0.2, 0.6) << Snapshot(100, 1e-3, 3, 0.0, 0.8)
      << Snapshot(200, 2e-3, 3, 0.1, 0.2);
  const Outcome r = Render(dir, dir / "frames.dump");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(Slurp(dir / "animation/animation.json"));
  EXPECT_EQ(j.at("frames").get<int>(), 3);
  EXPECT_EQ(j.at("elements").get<int>(), 3);
  EXPECT_NEAR(j.at("time_first_ms").get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(j.at("time_last_ms").get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(j.at("frame_interval_ms").get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(j.at("centroid_first_m")[0].get<double>(), -0.18, 1e-9);
  EXPECT_NEAR(j.at("centroid_first_m")[1].get<double>(), 0.6, 1e-9);
  EXPECT_NEAR(j.at("centroid_last_m")[0].get<double>(), 0.12, 1e-9);
  EXPECT_NEAR(j.at("centroid_last_m")[1].get<double>(), 0.2, 1e-9);
  EXPECT_NEAR(j.at("intact_bonds_first").get<double>(), 9.0, 1e-9);  // 3 x 6 / 2
  EXPECT_NEAR(j.at("intact_bonds_last").get<double>(), 6.0, 1e-9);
  EXPECT_EQ(j.at("caption").get<std::string>(), "lump 7 at 1000 rpm");
  EXPECT_GT(j.at("first_last_pixel_difference").get<double>(), 0.1) << j.dump(2);
  EXPECT_EQ(j.at("stills").at("middle").at("frame").get<int>(), 1);
  // The GIF holds the three frames (read back with PIL).
  const std::string count = kPython + " -c 'import sys; from PIL import Image; " +
                            "sys.exit(0 if Image.open(sys.argv[1]).n_frames == 3 else 1)' " +
                            (dir / "animation/animation.gif").string();
  EXPECT_EQ(std::system(count.c_str()), 0) << "the GIF does not hold 3 frames";
  for (const char* s : {"animation_first.png", "animation_middle.png", "animation_last.png"})
    EXPECT_GT(fs::file_size(dir / "animation" / s), 1000u) << s;
  EXPECT_NE(Slurp(dir / "animation/animation_first.png"),
            Slurp(dir / "animation/animation_last.png"));
}

TEST(PlotAnimation, MissingDumpNamesTheFile) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy/PIL";
  const auto dir = Fresh("missing");
  const Outcome r = Render(dir, dir / "nothing.dump");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find((dir / "nothing.dump").string() + ": cannot read the frame dump"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "animation/animation.gif"));
}

TEST(PlotAnimation, TruncatedSnapshotNamesTheFileAndStep) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy/PIL";
  const auto dir = Fresh("truncated");
  std::ofstream(dir / "frames.dump")
      << Snapshot(0, 0.0, 3, -0.2, 0.6) << Snapshot(100, 1e-3, 3, 0.0, 0.8, 1);
  const Outcome r = Render(dir, dir / "frames.dump");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find((dir / "frames.dump").string() +
                       ": the snapshot of step 100 has 2 of 3 element lines"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "animation/animation.gif"));
}

TEST(PlotAnimation, MissingColumnAndGarbageNameTheFileAndLine) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy/PIL";
  const auto dir = Fresh("column");
  std::string s = Snapshot(0, 0.0, 2, -0.2, 0.6);
  s.replace(s.find(" v_frame_time"), 13, "");
  std::ofstream(dir / "frames.dump") << s;
  Outcome r = Render(dir, dir / "frames.dump");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find((dir / "frames.dump").string() + ":9: missing column(s) v_frame_time"),
            std::string::npos)
      << r.err;
  std::ofstream(dir / "frames.dump") << Snapshot(0, 0.0, 2, -0.2, 0.6) << "garbage\n";
  r = Render(dir, dir / "frames.dump");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find((dir / "frames.dump").string() + ":12: expected 'ITEM: TIMESTEP'"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace mill::post
