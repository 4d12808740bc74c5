// Paths to test data, resolved at build time.
#pragma once

#include <string>

namespace vc::testing {

// Whether this test binary runs under AddressSanitizer: its quarantine keeps freed blocks resident
// (up to 256 MB), so tests of the process's resident memory cannot see a block's release there.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

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
