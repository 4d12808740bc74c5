// vc-client validate (validate_command.h): scans simulated in RoomWithClutterScene and written to
// files are read back with their positions from every source (a positions CSV, a PCD VIEWPOINT,
// each scan in its own frame, an E57 with poses); every input error names the file and scan; the
// PLY's colours are the report's sets; the table and validation.json carry the report's figures.
#include "vc/client/validate_command.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "testing/e57_writer.h"
#include "testing/test_paths.h"
#include "vc/synth/scanner_sim.h"

namespace vc::client {
namespace {

const WorldPoint kSecondStationM{6.0, 2.5, 1.2};

// A coarse simulated scan of RoomWithClutterScene from `position_m` (a few thousand points).
std::vector<Eigen::Vector3f> Simulate(const WorldPoint& position_m) {
  SimulatedScanner scanner;
  scanner.position_m = position_m;
  scanner.horizontal_step_deg = scanner.vertical_step_deg = 2.0;
  Result<SimulatedScan> scan = SimulateScan(RoomWithClutterScene(), scanner);
  EXPECT_TRUE(scan.ok()) << scan.status().ToString();
  return scan.ok() ? scan->points_m : std::vector<Eigen::Vector3f>{};
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string XyzText(const std::vector<Eigen::Vector3f>& points) {
  std::string out;
  char line[96];
  for (const Eigen::Vector3f& p : points) {
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f\n", p.x(), p.y(), p.z());
    out += line;
  }
  return out;
}

class ValidateCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = vc::testing::MakeTempDir();
    first_ = Simulate(kRoomWithClutterStationM);
    second_ = Simulate(kSecondStationM);
    WriteText(Path("a.xyz"), XyzText(first_));
    WriteText(Path("b.xyz"), XyzText(second_));
    WriteText(Path("positions.csv"), "x,y,z\n2,3,1.5\n6,2.5,1.2\n");
  }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  ValidateInputs TwoPointFiles() const { return {{Path("a.xyz"), Path("b.xyz")}, Path("positions.csv"), false}; }

  std::string dir_;
  std::vector<Eigen::Vector3f> first_, second_;
};

TEST_F(ValidateCommandTest, PointFilesTakeTheirPositionsInOrder) {
  Result<LoadedScans> loaded = LoadScans(TwoPointFiles(), 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->scans.size(), 2u);
  EXPECT_EQ(loaded->scans[0].name, Path("a.xyz"));
  EXPECT_TRUE(loaded->scans[1].position_m.isApprox(kSecondStationM));
  EXPECT_EQ(loaded->scans[0].points_m.size(), first_.size());
  EXPECT_EQ(loaded->scans[1].points_m.size(), second_.size());
  EXPECT_EQ(loaded->dropped_near_scanner, (std::vector<uint64_t>{0, 0}));
  EXPECT_FALSE(loaded->scans[0].heading_deg.has_value());  // positions.csv has no yaw column
}

TEST_F(ValidateCommandTest, SurveyCoordinatesGiveTheSameScansInALocalFrame) {
  const Eigen::Vector3d shift_m(512000, 5612000, 0);
  auto shifted = [&](const std::vector<Eigen::Vector3f>& points) {
    std::string out;
    char line[128];
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector3d q = p.cast<double>() + shift_m;
      std::snprintf(line, sizeof line, "%.6f %.6f %.6f\n", q.x(), q.y(), q.z());
      out += line;
    }
    return out;
  };
  WriteText(Path("a-utm.xyz"), shifted(first_));
  WriteText(Path("b-utm.xyz"), shifted(second_));
  WriteText(Path("positions-utm.csv"), "x,y,z\n512002,5612003,1.5\n512006,5612002.5,1.2\n");
  Result<LoadedScans> plain = LoadScans(TwoPointFiles(), 0.5);
  Result<LoadedScans> utm = LoadScans({{Path("a-utm.xyz"), Path("b-utm.xyz")}, Path("positions-utm.csv"), false}, 0.5);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  ASSERT_TRUE(utm.ok()) << utm.status().ToString();
  EXPECT_EQ(utm->frame_origin_m, shift_m);
  ASSERT_EQ(utm->scans.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_LT((utm->scans[i].position_m - plain->scans[i].position_m).norm(), 1e-9);
    ASSERT_EQ(utm->scans[i].points_m.size(), plain->scans[i].points_m.size());
    for (size_t k = 0; k < utm->scans[i].points_m.size(); ++k) {
      ASSERT_LT((utm->scans[i].points_m[k] - plain->scans[i].points_m[k]).norm(), 1e-5f)
          << "scan " << i << " point " << k;
    }
  }
}

TEST_F(ValidateCommandTest, PointsNearerThanTheMinimumRangeToTheirScannerAreDropped) {
  std::vector<Eigen::Vector3f> with_platform = first_;
  with_platform.push_back(kRoomWithClutterStationM.cast<float>() + Eigen::Vector3f(0.1f, 0, -0.2f));
  WriteText(Path("a.xyz"), XyzText(with_platform));
  Result<LoadedScans> loaded = LoadScans(TwoPointFiles(), 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->dropped_near_scanner[0], 1u);
  EXPECT_EQ(loaded->scans[0].points_m.size(), first_.size());
}

TEST_F(ValidateCommandTest, ScansInTheirOwnFramesAreMovedByPositionAndHeading) {
  const double heading_deg = 30.0;
  const Eigen::Isometry3d pose = Eigen::Translation3d(kSecondStationM) *
                                 Eigen::AngleAxisd(heading_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitZ());
  std::vector<Eigen::Vector3f> own_frame;
  for (const Eigen::Vector3f& p : second_) own_frame.push_back((pose.inverse() * p.cast<double>()).cast<float>());
  WriteText(Path("b_own.xyz"), XyzText(own_frame));
  WriteText(Path("a_own.xyz"), XyzText([&] {
              std::vector<Eigen::Vector3f> out;
              for (const Eigen::Vector3f& p : first_) out.push_back(p - kRoomWithClutterStationM.cast<float>());
              return out;
            }()));
  WriteText(Path("poses.csv"), "x,y,z,yaw\n2,3,1.5,0\n6,2.5,1.2,30\n");
  Result<LoadedScans> loaded = LoadScans({{Path("a_own.xyz"), Path("b_own.xyz")}, Path("poses.csv"), true}, 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->scans[1].points_m.size(), second_.size());
  for (size_t i = 0; i < second_.size(); i += 97) {
    EXPECT_LT((loaded->scans[1].points_m[i] - second_[i]).norm(), 1e-4f) << i;
  }
  EXPECT_LT((loaded->scans[0].points_m[0] - first_[0]).norm(), 1e-4f);
  // The yaw column is each scan's heading, which --hfov below 360 needs.
  ASSERT_TRUE(loaded->scans[0].heading_deg && loaded->scans[1].heading_deg);
  EXPECT_DOUBLE_EQ(*loaded->scans[0].heading_deg, 0.0);
  EXPECT_NEAR(*loaded->scans[1].heading_deg, heading_deg, 1e-9);
}

TEST_F(ValidateCommandTest, APcdTakesItsPositionFromItsViewpoint) {
  WriteText(Path("b.pcd"), "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " +
                               std::to_string(second_.size()) + "\nHEIGHT 1\nVIEWPOINT 6 2.5 1.2 1 0 0 0\nPOINTS " +
                               std::to_string(second_.size()) + "\nDATA ascii\n" + XyzText(second_));
  Result<LoadedScans> loaded = LoadScans({{Path("b.pcd")}, "", false}, 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_TRUE(loaded->scans[0].position_m.isApprox(kSecondStationM));
  EXPECT_EQ(loaded->scans[0].points_m.size(), second_.size());
}

TEST_F(ValidateCommandTest, AnE57GivesEachOfItsScansWithItsPose) {
  vc::testing::E57Spec spec;
  for (const auto& [points, position] : {std::pair{first_, kRoomWithClutterStationM}, {second_, kSecondStationM}}) {
    vc::testing::E57ScanSpec scan;
    scan.translation_m = position;
    // The second scan is turned by a yaw of 30 deg: its heading.
    if (position == kSecondStationM) {
      scan.rotation = Eigen::AngleAxisd(30 * std::numbers::pi / 180, Eigen::Vector3d::UnitZ());
    }
    for (const Eigen::Vector3f& p : points)
      scan.points.push_back(scan.rotation.inverse() * (p.cast<double>() - position));
    scan.packets = int(points.size() / 1000) + 2;  // the writer's packets hold up to 64 KiB
    spec.scans.push_back(scan);
  }
  WriteText(Path("two.e57"), vc::testing::WriteE57(spec));
  Result<LoadedScans> loaded = LoadScans({{Path("two.e57")}, "", false}, 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->scans.size(), 2u);
  EXPECT_EQ(loaded->scans[1].name, Path("two.e57") + ", scan 2 (scan)");
  EXPECT_TRUE(loaded->scans[1].position_m.isApprox(kSecondStationM));
  ASSERT_EQ(loaded->scans[1].points_m.size(), second_.size());
  EXPECT_LT((loaded->scans[1].points_m.back() - second_.back()).norm(), 2e-3f);  // E57 scale 1 mm
  ASSERT_TRUE(loaded->scans[0].heading_deg && loaded->scans[1].heading_deg);
  EXPECT_NEAR(*loaded->scans[0].heading_deg, 0.0, 1e-9);
  EXPECT_NEAR(*loaded->scans[1].heading_deg, 30.0, 1e-9);
}

TEST_F(ValidateCommandTest, AnE57WithDroppedRecordsIsRefusedNamingTheFile) {
  vc::testing::E57Spec spec;
  vc::testing::E57ScanSpec scan;
  for (size_t i = 0; i < 100; ++i) scan.points.push_back(first_[i].cast<double>());
  scan.invalid_state.assign(100, 0);
  scan.invalid_state[5] = 2;
  spec.scans = {scan, scan};
  WriteText(Path("dropped.e57"), vc::testing::WriteE57(spec));
  Result<LoadedScans> loaded = LoadScans({{Path("dropped.e57")}, "", false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(loaded.status().message().find(Path("dropped.e57")), std::string::npos) << loaded.status().message();
}

TEST_F(ValidateCommandTest, PositionsWithOnlyE57FilesAreRefused) {
  vc::testing::E57Spec spec;
  vc::testing::E57ScanSpec scan;
  for (size_t i = 0; i < 100; ++i) scan.points.push_back(first_[i].cast<double>());
  spec.scans = {scan};
  WriteText(Path("one.e57"), vc::testing::WriteE57(spec));
  Result<LoadedScans> loaded = LoadScans({{Path("one.e57")}, Path("positions.csv"), false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(loaded.status().message().find("--positions " + Path("positions.csv") + ": no point file"),
            std::string::npos)
      << loaded.status().message();
}

TEST_F(ValidateCommandTest, APointFileWithoutAPositionIsRefusedNamingFileAndScan) {
  Result<LoadedScans> loaded = LoadScans({{Path("a.xyz"), Path("b.xyz")}, "", false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(loaded.status().message().find(Path("a.xyz") + " (scan 1) has no scanner position"), std::string::npos)
      << loaded.status().message();
}

TEST_F(ValidateCommandTest, PositionsAndFilesThatDoNotMatchInNumberAreRefused) {
  WriteText(Path("three.csv"), "1,1,1\n2,2,2\n3,3,1\n");
  Result<LoadedScans> loaded = LoadScans({{Path("a.xyz"), Path("b.xyz")}, Path("three.csv"), false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(loaded.status().message().find(Path("three.csv") + " holds 3 positions but 2 point files"),
            std::string::npos)
      << loaded.status().message();
}

TEST_F(ValidateCommandTest, AnUnreadableFileIsRefusedNamingIt) {
  Result<LoadedScans> loaded = LoadScans({{Path("a.xyz"), Path("missing.xyz")}, Path("positions.csv"), false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kNotFound);
  EXPECT_NE(loaded.status().message().find(Path("missing.xyz") + " (scan 2): "), std::string::npos)
      << loaded.status().message();
  WriteText(Path("garbage.xyz"), "1 2 three\n");
  loaded = LoadScans({{Path("a.xyz"), Path("garbage.xyz")}, Path("positions.csv"), false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find(Path("garbage.xyz") + " (scan 2): "), std::string::npos)
      << loaded.status().message();
}

TEST_F(ValidateCommandTest, APoseOutsideTheSceneIsRefusedNamingFileAndScan) {
  WriteText(Path("far.csv"), "2,3,1.5\n600,2.5,1.2\n");
  Result<LoadedScans> loaded = LoadScans({{Path("a.xyz"), Path("b.xyz")}, Path("far.csv"), false}, 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  Result<ValidationReport> report = ValidateAgainstScans(loaded->scans, ValidationOptions{});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(report.status().message().find("scan 2 (\"" + Path("b.xyz") + "\")"), std::string::npos)
      << report.status().message();
}

TEST_F(ValidateCommandTest, AScanWithNoPointBeyondTheMinimumRangeIsRefusedNamingIt) {
  WriteText(Path("platform.xyz"), "2.1 3 1.4\n2 3.1 1.3\n");
  WriteText(Path("one.csv"), "2,3,1.5\n");
  Result<LoadedScans> loaded = LoadScans({{Path("platform.xyz")}, Path("one.csv"), false}, 0.5);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("scan 1 (" + Path("platform.xyz") + ")"), std::string::npos)
      << loaded.status().message();
}

// The PLY's vertices: position and colour, read back from the binary body.
struct PlyVertex {
  Eigen::Vector3f position;
  std::array<uint8_t, 3> rgb;
};
std::vector<PlyVertex> ReadPly(const std::string& ply, std::string* header) {
  const size_t end = ply.find("end_header\n") + std::strlen("end_header\n");
  *header = ply.substr(0, end);
  std::vector<PlyVertex> out;
  for (size_t at = end; at + 15 <= ply.size(); at += 15) {
    PlyVertex v;
    std::memcpy(v.position.data(), ply.data() + at, 12);
    std::memcpy(v.rgb.data(), ply.data() + at + 12, 3);
    out.push_back(v);
  }
  return out;
}

TEST_F(ValidateCommandTest, ThePlyColoursEachModelVoxelByTheSets) {
  Result<LoadedScans> loaded = LoadScans(TwoPointFiles(), 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ValidationOptions options;
  options.keep_sets = true;
  Result<ValidationReport> report = ValidateAgainstScans(loaded->scans, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  for (size_t s = 0; s < 2; ++s) {
    Result<std::string> ply = ValidationPly(*report, s);
    ASSERT_TRUE(ply.ok()) << ply.status().ToString();
    std::string header;
    const std::vector<PlyVertex> vertices = ReadPly(*ply, &header);
    EXPECT_NE(header.find("comment colour: red 230 40 40 = missed"), std::string::npos) << header;
    ASSERT_EQ(vertices.size(), report->model.occupied.size());
    const ScanAgreement& a = report->scans[s];
    uint64_t agree = 0, missed = 0, over = 0;
    for (size_t id = 0; id < vertices.size(); ++id) {
      EXPECT_LT((vertices[id].position - report->model.Center(id).cast<float>()).norm(), 1e-4f);
      const bool c = a.captured_set.test(id), p = a.predicted_set.test(id);
      const auto expected = c && p ? kAgreeRgb : c ? kMissedRgb : p ? kOverPredictedRgb : kNeitherRgb;
      ASSERT_EQ(vertices[id].rgb, expected) << "scan " << s + 1 << " voxel " << id;
      agree += vertices[id].rgb == kAgreeRgb;
      missed += vertices[id].rgb == kMissedRgb;
      over += vertices[id].rgb == kOverPredictedRgb;
    }
    EXPECT_EQ(agree, a.both);
    EXPECT_EQ(missed, a.captured - a.both);
    EXPECT_EQ(over, a.predicted - a.both);
    EXPECT_GT(agree, 0u);
    EXPECT_GT(missed + over, 0u);
  }
  EXPECT_EQ(ValidationPly(*report, 2).status().code(), StatusCode::kInvalidArgument);
  report->model = VoxelScene{};
  EXPECT_EQ(ValidationPly(*report, 0).status().code(), StatusCode::kFailedPrecondition);
}

TEST_F(ValidateCommandTest, OutputsCarryTheReportsFigures) {
  const ValidateInputs inputs = TwoPointFiles();
  Result<LoadedScans> loaded = LoadScans(inputs, 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ValidationOptions options;
  options.keep_sets = true;
  options.selection_test = SelectionTest::kCompatibility;
  Result<ValidationReport> report = ValidateAgainstScans(loaded->scans, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const std::string out = dir_ + "/out";
  ASSERT_TRUE(WriteValidationOutputs(*report, inputs, *loaded, options.scanner, out).ok());
  const auto j = nlohmann::json::parse(vc::testing::ReadFileBytes(out + "/validation.json"));
  EXPECT_EQ(j["selection_test"], "compatibility");
  EXPECT_EQ(j["positions_file"], Path("positions.csv"));
  ASSERT_EQ(j["scans"].size(), 2u);
  EXPECT_EQ(j["scans"][1]["captured"].get<uint64_t>(), report->scans[1].captured);
  EXPECT_EQ(j["scans"][1]["recall_slack"].get<double>(), report->scans[1].recall_slack);
  EXPECT_EQ(j["scans"][0]["position_m"][1].get<double>(), 3.0);
  EXPECT_TRUE(j["scans"][0]["heading_deg"].is_null());  // positions.csv has no yaw
  EXPECT_EQ(j["scanner"]["hfov_deg"].get<double>(), 360.0);
  EXPECT_EQ(vc::testing::ReadFileBytes(out + "/validation_2.ply"), *ValidationPly(*report, 1));

  const std::string table = ValidationTable(*report);
  char recall[16];
  std::snprintf(recall, sizeof recall, "%.3f", report->scans[0].recall);
  EXPECT_NE(table.find(recall), std::string::npos) << table;
  EXPECT_EQ(table.find("note:"), std::string::npos) << table;
}

// --hfov below 360 needs each scan's heading: positions without a yaw column are refused naming
// the scan's file; with one the validation runs and predicts no more than all round.
TEST_F(ValidateCommandTest, AFieldOfViewBelow360NeedsAYawPerScan) {
  ValidationOptions options;
  options.scanner.hfov_deg = 182;
  Result<LoadedScans> loaded = LoadScans(TwoPointFiles(), 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  Result<ValidationReport> refused = ValidateAgainstScans(loaded->scans, options);
  ASSERT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find(Path("a.xyz") + "\") has no heading"), std::string::npos)
      << refused.status().ToString();
  WriteText(Path("positions.csv"), "x,y,z,yaw\n2,3,1.5,0\n6,2.5,1.2,180\n");
  loaded = LoadScans(TwoPointFiles(), 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  Result<ValidationReport> sector = ValidateAgainstScans(loaded->scans, options);
  Result<ValidationReport> all_round = ValidateAgainstScans(loaded->scans, ValidationOptions{});
  ASSERT_TRUE(sector.ok() && all_round.ok()) << sector.status().ToString();
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_LT(sector->scans[i].predicted, all_round->scans[i].predicted) << i;
    EXPECT_GT(sector->scans[i].predicted, 0u) << i;
  }
}

TEST_F(ValidateCommandTest, ASingleScansTableSaysOnlyRecallIsMeaningful) {
  WriteText(Path("one.csv"), "2,3,1.5\n");
  Result<LoadedScans> loaded = LoadScans({{Path("a.xyz")}, Path("one.csv"), false}, 0.5);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  Result<ValidationReport> report = ValidateAgainstScans(loaded->scans, ValidationOptions{});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const std::string table = ValidationTable(*report);
  EXPECT_NE(table.find("note: "), std::string::npos) << table;
  EXPECT_NE(table.find("        -"), std::string::npos) << table;  // precision not shown
}

TEST(ValidateCommandFlags, ParseTheTestTheScannerAndTheInputs) {
  CLI::App app;
  ValidateCommand command;
  AddValidateCommand(app, &command);
  app.parse(
      "validate a.xyz b.xyz --positions p.csv --test compatibility --max-range 30 --hfov 182 --resolution 0.05 --out o",
      false);
  EXPECT_EQ(command.options.scanner.hfov_deg, 182.0);
  EXPECT_EQ(command.inputs.positions_file, "p.csv");
  EXPECT_EQ(command.options.selection_test, SelectionTest::kCompatibility);
  EXPECT_EQ(command.options.scanner.max_range_m, 30.0);
  EXPECT_EQ(command.options.resolution_m, 0.05);
  EXPECT_EQ(command.out_dir, "o");
  EXPECT_EQ(command.inputs.files, (std::vector<std::string>{"a.xyz", "b.xyz"}));
  EXPECT_FALSE(command.inputs.scanner_frame);
}

TEST(ValidateCommandFlags, AScannerPresetFillsTheLimitsItsFlagsDoNotGive) {
  CLI::App app;
  ValidateCommand command;
  AddValidateCommand(app, &command);
  app.parse("validate a.pcd --scanner leica-blk360-g2 --max-range 30 --scanner-frame", false);
  EXPECT_EQ(command.options.scanner.name, "leica-blk360-g2");
  EXPECT_EQ(command.options.scanner.max_range_m, 30.0);    // the flag
  EXPECT_EQ(command.options.scanner.vfov_min_deg, -45.0);  // the preset
  EXPECT_EQ(command.options.selection_test, SelectionTest::kSurfaceVisibility);
  EXPECT_TRUE(command.inputs.scanner_frame);
  EXPECT_TRUE(command.inputs.positions_file.empty());
}

}  // namespace
}  // namespace vc::client
