#include "testing/survey.h"

#include <sstream>

namespace vc::testing {

std::vector<Eigen::Vector3d> SurveyPoints() {
  return {{512345.678, 5612330.123, 312.5},
          {512345.679, 5612330.124, 312.501},
          {512350.001, 5612325.999, 310.25},
          {512339.987, 5612333.333, 315.004},
          {512341.5, 5612338.75, 311.125}};
}

std::vector<Eigen::Vector3d> Shifted(std::vector<Eigen::Vector3d> points, const Eigen::Vector3d& shift_m) {
  for (Eigen::Vector3d& p : points) p += shift_m;
  return points;
}

::testing::AssertionResult HoldsInInputFrame(const SceneInput& in, const std::vector<Eigen::Vector3d>& expected_m,
                                             double tolerance_m) {
  if (in.points.size() != expected_m.size()) {
    return ::testing::AssertionFailure() << in.points.size() << " points, expected " << expected_m.size();
  }
  for (size_t i = 0; i < expected_m.size(); ++i) {
    const Eigen::Vector3d input_frame = in.points[i].cast<double>() + in.frame_origin_m;
    const double error_m = (input_frame - expected_m[i]).cwiseAbs().maxCoeff();
    if (!(error_m <= tolerance_m)) {
      std::ostringstream os;
      os.precision(12);
      os << "point " << i << " reads as " << input_frame.transpose() << " (local " << in.points[i].transpose()
         << " + origin " << in.frame_origin_m.transpose() << "), expected " << expected_m[i].transpose() << ": off by "
         << error_m << " m";
      return ::testing::AssertionFailure() << os.str();
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace vc::testing
