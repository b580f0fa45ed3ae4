// A fresh empty temporary directory per test, for the postprocess/ tests.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace mill::post {

// A fresh empty directory named after the running test.
inline std::filesystem::path TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (std::string("mill_post_") + info->test_suite_name() + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace mill::post
