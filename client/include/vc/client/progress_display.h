// ProgressDisplay: the live progress of a job on a terminal (one redrawn bar with the stage name),
// or plain lines when the output is not a terminal (a line per stage and per quarter of a stage).
// Not thread-safe (the client calls it from one thread).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "vc/base/progress.h"
#include "vc/plan/planner.h"

namespace vc::client {

class ProgressDisplay {
 public:
  // `tty`: redraw one line in place (use isatty(fileno(out))).
  ProgressDisplay(std::FILE* out, bool tty) : out_(out), tty_(tty) {}
  void Uploading(const std::string& source, uint64_t bytes, const std::string& server);
  void Accepted(const std::string& job_id, uint32_t queue_position);
  void Update(const ProgressEvent& e);
  // A provisional pick of the greedy selection (`index` from 0).
  void Station(const PlannedStation& s, int index);
  // The final stations, after refinement and reduction.
  void FinalStations(const std::vector<PlannedStation>& stations);
  void Note(const std::string& line);
  // Ends the bar's line.
  void Done();

 private:
  void ClearBar();
  std::FILE* out_;
  bool tty_;
  bool bar_shown_ = false;
  Stage stage_ = Stage::kUnspecified;
  int last_quarter_ = -1;
};

}  // namespace vc::client
