// Points at survey coordinates (a UTM-like frame: x ~ 512 km, y ~ 5,612 km) for the local-frame
// tests of every reader (docs/PLANNING.md "Coordinates").
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <vector>

#include "vc/scene/scene_input.h"

namespace vc::testing {

// The frame origin ReadScene chooses for SurveyPoints(), in metres.
inline const Eigen::Vector3d kSurveyOrigin(512000, 5612000, 0);

// Five points within 10 m of (512,345.678, 5,612,330.123, 312.5) m, each with millimetres in its
// coordinates, input frame.
std::vector<Eigen::Vector3d> SurveyPoints();

// `points` each moved by `shift_m`.
std::vector<Eigen::Vector3d> Shifted(std::vector<Eigen::Vector3d> points, const Eigen::Vector3d& shift_m);

// Success if `in` holds exactly `expected_m` (input frame, metres), in order, each local point plus
// in.frame_origin_m (in double) within `tolerance_m` of it.
::testing::AssertionResult HoldsInInputFrame(const SceneInput& in, const std::vector<Eigen::Vector3d>& expected_m,
                                             double tolerance_m);

}  // namespace vc::testing
