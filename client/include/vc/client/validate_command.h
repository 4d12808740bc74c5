// `vc-client validate`: how far a selection test's prediction agrees with the user's own scans
// (issue 34; docs/VISIBILITY.md "Measured against captured points"). It runs locally, like
// inspect: the scans are the user's own files and the work is one visibility pass per scan, so no
// server is involved.
//
// Inputs: E57 files (each of their scans with its pose), or point files (PLY, PCD, XYZ, LAS), one
// scan per file, whose scanner positions come from --positions FILE (anything ReadStationFile
// reads, one position per point file in order) or from a PCD's own VIEWPOINT. By default a point
// file's points are in the common frame the positions are given in; with --scanner-frame each file
// is in its own scanner's frame and is moved by its position and heading (yaw only: roll and pitch
// are not applied). Points nearer than the scanner's min_range_m to their own scanner are dropped
// (returns from the tripod or platform, which a scanner cannot capture at that range).
//
// Outputs: a table per scan on stdout and, with --out DIR, validation.json and validation_<n>.ply
// (n from 1: the model's voxels coloured agree / missed / over-predicted / neither).
// Thread-safety: the functions share no state.
#pragma once

#include <CLI/CLI.hpp>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vc/base/status.h"
#include "vc/visibility/validation.h"

namespace vc::client {

// What the user named: the files and how their scanner positions are given.
struct ValidateInputs {
  // E57 files and point files, in order (a point file is one scan).
  std::vector<std::string> files;
  // Scanner positions of the point files, one per point file in order; empty = each PCD's VIEWPOINT.
  std::string positions_file;
  // Each point file is in its own scanner's frame: move it by its position and heading.
  bool scanner_frame = false;
};

// The scans read from ValidateInputs, in one frame (m), each named "FILE" or "FILE, scan N (NAME)".
struct LoadedScans {
  std::vector<CapturedScan> scans;
  // Per scan: points dropped because they lie nearer than min_range_m to the scan's own scanner.
  std::vector<uint64_t> dropped_near_scanner;
};

// Reads the scans of `inputs`, dropping points nearer than `min_range_m` to their scanner.
// INVALID_ARGUMENT naming the file and scan for: a point file without a position (no --positions,
// and not a PCD with a VIEWPOINT), a number of positions that differs from the number of point
// files, --positions with only E57 files, an octree or .graph file (no per-scan points), an E57 whose
// dropped records cannot be assigned to their scans, or a scan left without points; NOT_FOUND /
// INVALID_ARGUMENT naming the file and its scan ("FILE (scan N): ...") when a file cannot be read or parsed.
Result<LoadedScans> LoadScans(const ValidateInputs& inputs, double min_range_m);

// The table printed on stdout: one line per scan (captured, predicted, both, recall and precision
// with no slack and with one voxel of slack), and the report's note for a single scan.
std::string ValidationTable(const ValidationReport& report);

// validation.json: the inputs, the selection test, the resolution, the scanner limits and each
// scan's figures (docs/VISIBILITY.md, "Measured against captured points").
std::string ValidationToJson(const ValidationReport& report, const ValidateInputs& inputs, const LoadedScans& loaded,
                             const ScannerModel& scanner);

// The colours of validation_<n>.ply: captured and predicted; captured, not predicted; predicted,
// not captured; a model voxel this scan neither captured nor is predicted to see.
inline constexpr std::array<uint8_t, 3> kAgreeRgb{40, 180, 40};
inline constexpr std::array<uint8_t, 3> kMissedRgb{230, 40, 40};
inline constexpr std::array<uint8_t, 3> kOverPredictedRgb{40, 90, 230};
inline constexpr std::array<uint8_t, 3> kNeitherRgb{160, 160, 160};

// validation_<scan + 1>.ply's bytes: every voxel of report.model at its centre (m), coloured as
// above. FAILED_PRECONDITION unless the report kept its sets (ValidationOptions::keep_sets);
// INVALID_ARGUMENT for a scan index out of range.
Result<std::string> ValidationPly(const ValidationReport& report, size_t scan);

// Writes validation.json and validation_<n>.ply for every scan into `out_dir` (created if missing).
// Errors as ValidationPly, and INTERNAL naming the path on I/O errors.
Status WriteValidationOutputs(const ValidationReport& report, const ValidateInputs& inputs, const LoadedScans& loaded,
                              const ScannerModel& scanner, const std::string& out_dir);

// The command line of `validate`.
struct ValidateCommand {
  ValidateInputs inputs;
  ValidationOptions options;
  // Empty: print the table only.
  std::string out_dir;
};

// Adds the `validate` subcommand to `app`, bound to `command` (which must outlive the parse).
CLI::App* AddValidateCommand(CLI::App& app, ValidateCommand* command);

// Runs `validate`: loads, validates, prints the table, writes the outputs. Returns the exit status
// (0, or the gRPC code number of the failure, as vc-client's other local errors), messages on stderr.
int RunValidate(const ValidateCommand& command);

}  // namespace vc::client
