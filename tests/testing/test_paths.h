// Paths to test data, resolved at build time.
#pragma once

#include <string>

namespace vc::testing {

// ../shared/data beside the checkout (real scans; see its README).
std::string SharedDataPath(const std::string& relative);
// tests/data in the checkout (small hand-made fixtures).
std::string TestDataPath(const std::string& relative);
// The build directory (where the binaries are).
std::string BinaryDir();
// A fresh, empty temporary directory unique to the calling test. Removed when the test program
// exits, unless a test failed (then they are kept for inspection, and their paths printed).
std::string MakeTempDir();
// The whole content of the file at `path` (bytes); empty if it cannot be read.
std::string ReadFileBytes(const std::string& path);
// The standard output of the shell command `command` (popen); empty if it cannot be started.
std::string CommandOutput(const std::string& command);

}  // namespace vc::testing
