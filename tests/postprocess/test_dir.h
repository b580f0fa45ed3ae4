// A fresh empty temporary directory per test, for the postprocess/ tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "temp_dir.h"

namespace mill::post {

// A fresh empty directory named after the running test (and this process),
// removed when the test passes, kept when it fails.
inline mill::test::TempDir TestDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return mill::test::TempDir(std::string("mill_post_") + info->test_suite_name() + "_" +
                             info->name() + "_" + std::to_string(getpid()));
}

}  // namespace mill::post
