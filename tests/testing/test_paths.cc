#include "testing/test_paths.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <vector>

namespace vc::testing {
namespace {

// The directories MakeTempDir made in this process, removed at exit if every test passed.
class TempDirs {
 public:
  void Add(const std::filesystem::path& dir) {
    const std::lock_guard<std::mutex> lock(mu_);
    dirs_.push_back(dir);
  }
  ~TempDirs() {
    const bool failed = ::testing::UnitTest::GetInstance()->Failed();
    for (const auto& dir : dirs_) {
      if (failed) {
        std::cerr << "kept for inspection: " << dir.string() << "\n";
        continue;
      }
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    }
  }

 private:
  std::mutex mu_;
  std::vector<std::filesystem::path> dirs_;
};

TempDirs& Made() {
  static TempDirs dirs;
  return dirs;
}

}  // namespace

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
  Made().Add(dir);
  return dir.string();
}

std::string ReadFileBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string CommandOutput(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof(buf), pipe)) > 0;) out.append(buf, n);
  pclose(pipe);
  return out;
}

}  // namespace vc::testing
