// Writes the E57 fuzz seeds (fuzz/corpus/e57_fuzzer/) with the tests' E57 writer.
// Usage: write_e57_seeds DIR
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "testing/e57_writer.h"

namespace {

using vc::testing::E57Coordinates;
using vc::testing::E57ScanSpec;
using vc::testing::E57Spec;
using vc::testing::E57ValueType;

E57ScanSpec Scan(E57ValueType type, int n) {
  E57ScanSpec s;
  s.type = type;
  for (int i = 0; i < n; ++i) s.points.emplace_back(0.5 * i, 2.0 - 0.25 * i, std::fmod(0.3 * i, 2.0));
  return s;
}

bool Write(const std::string& path, const E57Spec& spec) {
  std::ofstream out(path, std::ios::binary);
  out << vc::testing::WriteE57(spec);
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_e57_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  E57Spec two;
  two.scans = {Scan(E57ValueType::kFloatDouble, 8), Scan(E57ValueType::kScaledInteger, 8)};
  two.scans[1].name = "second";
  two.scans[1].translation_m = {4, -2, 1.5};
  two.scans[1].rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  two.scans[1].extra_packets = true;
  two.scans[1].packets = 3;

  E57Spec spherical;
  spherical.scans = {Scan(E57ValueType::kFloatSingle, 12)};
  spherical.scans[0].coordinates = E57Coordinates::kSpherical;
  spherical.scans[0].invalid_state = {0, 0, 1, 0, 2, 0, 0, 0, 0, 0, 0, 0};
  spherical.scans[0].intensity = true;

  E57Spec integer;
  integer.scans = {Scan(E57ValueType::kInteger, 6)};
  integer.scans[0].write_pose = false;

  const bool ok = Write(dir + "/two_scans.e57", two) && Write(dir + "/spherical_single.e57", spherical) &&
                  Write(dir + "/integer.e57", integer);
  if (!ok) std::fprintf(stderr, "write_e57_seeds: cannot write under %s\n", dir.c_str());
  return ok ? 0 : 1;
}
