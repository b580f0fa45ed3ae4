// The shared HDF5 plumbing (h5_util.h) and the one wording of HDF5 errors in
// every writer and reader that uses it: breakage.h5, transport.h5, the flow field.
#include "postprocess/h5_util.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "postprocess/breakage_results.h"
#include "postprocess/flow_field_io.h"
#include "postprocess/fragments.h"
#include "postprocess/transport_h5.h"
#include "test_dir.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;

// A text file that is not HDF5.
std::string TextFile(const fs::path& dir) {
  const fs::path p = dir / "not_hdf5.h5";
  std::ofstream(p) << "plain text, not HDF5\n";
  return p.string();
}

// The PostError message of f, and that HDF5 printed nothing to stderr meanwhile.
std::string QuietError(const std::function<void()>& f) {
  ::testing::internal::CaptureStderr();
  std::string message = "(no error)";
  try {
    f();
  } catch (const PostError& e) {
    message = e.what();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "") << "HDF5 printed its error stack";
  return message;
}

// A one-impact breakage result, enough for the writers.
ImpactResult OneImpact() {
  std::vector<Element> e(3);
  for (int i = 0; i < 3; ++i) {
    e[i].id = i + 1;
    e[i].radius = 1e-3;
    e[i].mass = SphereMass(1e-3, 2600.0);
  }
  ImpactSpec spec;
  spec.conditions = {20.0, 90.0, 0};
  spec.initial_bonds = 2;
  spec.lump_diameter_m = 0.005;
  spec.density_kg_m3 = 2600.0;
  return AnalyseImpact(e, {{1, 2}}, spec);
}

TEST(H5Util, WhereNamesTheFileAndTheObject) {
  const auto dir = TestDir();
  const std::string path = (dir / "w.h5").string();
  h5::WriteFileAtomically(path, path + ".tmp", [&](hid_t file) {
    EXPECT_EQ(h5::Where(file), path + ".tmp");
    const h5::Handle g = h5::CreateGroup(file, "group");
    h5::WriteDataset(g, "values", std::vector<double>{1, 2}, {2}, "m");
    const h5::Handle d(H5Dopen2(g, "values", H5P_DEFAULT), H5Dclose, g, "open dataset 'values'");
    EXPECT_EQ(h5::Where(d), path + ".tmp:/group/values");
    try {
      h5::Check(-1, g, "do the thing");
      ADD_FAILURE() << "Check let a negative status pass";
    } catch (const PostError& e) {
      EXPECT_EQ(std::string(e.what()), path + ".tmp:/group: HDF5 could not do the thing");
    }
  });
  EXPECT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(H5Util, HandleClosesItsId) {
  hid_t id = -1;
  {
    const h5::Handle space(H5Screate(H5S_SCALAR), H5Sclose, "nowhere.h5", "make a space");
    id = space;
    EXPECT_GT(H5Iis_valid(id), 0);
  }
  EXPECT_EQ(H5Iis_valid(id), 0);
}

TEST(H5Util, FailedWriteLeavesNoFile) {
  const auto dir = TestDir();
  const std::string path = (dir / "x.h5").string();
  const std::string m = QuietError([&] {
    h5::WriteFileAtomically(path, path + ".tmp", [](hid_t file) {
      h5::WriteStringAttr(file, "a", "1");
      h5::WriteStringAttr(file, "a", "2");  // exists already
    });
  });
  EXPECT_EQ(m, path + ".tmp: HDF5 could not create attribute 'a'");
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(H5Errors, BreakageWritersNameTheFileAndOperation) {
  const auto dir = TestDir();
  const std::string text = TextFile(dir);
  EXPECT_EQ(QuietError([&] { MergeBreakageH5Files((dir / "m.h5").string(), {text}); }),
            text + ": HDF5 could not open the file for reading (missing, not HDF5, or damaged?)");
  EXPECT_FALSE(fs::exists(dir / "m.h5.tmp"));
  EXPECT_EQ(QuietError([&] { WriteJkFitH5(text, {}); }),
            text + ": HDF5 could not open the file for writing (missing, not HDF5, or damaged?)");
  EXPECT_EQ(QuietError([&] { WriteEnergyLedgerH5(text, EnergyLedger{}); }),
            text + ": HDF5 could not open the file for writing (missing, not HDF5, or damaged?)");
  const std::string missing = (dir / "no_such_folder" / "breakage.h5").string();
  EXPECT_EQ(
      QuietError([&] { WriteBreakageH5(missing, {OneImpact()}); }),
      missing +
          ".tmp: HDF5 could not create the file (does its folder exist, and may it be written?)");

  // Two fits of one name: the second group cannot be made, and the message
  // names the group it was to go in.
  const std::string path = (dir / "breakage.h5").string();
  WriteBreakageH5(path, {OneImpact()});
  JkFitRecord rec;
  rec.name = "a90";
  EXPECT_EQ(QuietError([&] {
              WriteJkFitH5(path, {rec, rec});
            }),
            path + ":/jk_fit: HDF5 could not create group 'a90'");
}

TEST(H5Errors, TransportWriterNamesTheFileAndLeavesNoTemp) {
  const auto dir = TestDir();
  const std::string path = (dir / "no_such_folder" / "transport.h5").string();
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  EXPECT_EQ(
      QuietError([&] { WriteTransportH5(path, {}, TransportStats{}, {}, Trajectories{}, {}); }),
      tmp + ": HDF5 could not create the file (does its folder exist, and may it be written?)");

  // A scalar named like the root attribute "content": the attribute exists.
  const std::string clash = (dir / "transport.h5").string();
  TransportMeta meta;
  meta.scalars = {{"content", 1.0}};
  EXPECT_EQ(
      QuietError([&] { WriteTransportH5(clash, {}, TransportStats{}, {}, Trajectories{}, meta); }),
      clash + ".tmp." + std::to_string(getpid()) + ": HDF5 could not create attribute 'content'");
  EXPECT_FALSE(fs::exists(clash));
  EXPECT_FALSE(fs::exists(clash + ".tmp." + std::to_string(getpid())));
}

TEST(H5Errors, FlowFieldReaderNamesTheFile) {
  const auto dir = TestDir();
  const std::string text = TextFile(dir);
  EXPECT_EQ(QuietError([&] { read_flow_field(text); }),
            text + ": HDF5 could not open the file for reading (missing, not HDF5, or damaged?)");
  EXPECT_EQ(QuietError([&] { dataset_unit(text, "U"); }),
            text + ": HDF5 could not open the file for reading (missing, not HDF5, or damaged?)");
}

}  // namespace
}  // namespace mill::post
