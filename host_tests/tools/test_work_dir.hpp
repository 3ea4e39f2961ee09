#pragma once
// The folder a test of the image tools writes its files into: its own, under
// CDCR_TEST_WORK_DIR (set by the build), named after the test and emptied
// first, so a rerun never reads what an earlier run left.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace cdcr::test_support {

inline std::filesystem::path fresh_test_work_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(CDCR_TEST_WORK_DIR) / (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace cdcr::test_support
