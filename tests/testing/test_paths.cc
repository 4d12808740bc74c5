#include "testing/test_paths.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <unistd.h>

namespace vc::testing {

std::string SharedDataPath(const std::string& relative) { return std::string(VC_SHARED_DATA_DIR) + "/" + relative; }
std::string TestDataPath(const std::string& relative) { return std::string(VC_TEST_DATA_DIR) + "/" + relative; }
std::string BinaryDir() { return VC_BINARY_DIR; }

std::string MakeTempDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "vc";
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  auto dir = std::filesystem::temp_directory_path() /
             ("vc-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace vc::testing
