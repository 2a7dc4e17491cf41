#pragma once
// Progress of a run on stderr: frame, substeps, percentage and ETA. On a terminal it redraws one
// line; in a log (CI, a pipe) it prints a line every 10% so the log stays short.
#include <chrono>
#include <cstdio>
#include <string>

namespace msim::scene {

class ProgressBar {
 public:
  ProgressBar(int firstFrame, int lastFrame, std::FILE* stream = stderr);
  // Called after frame `frame` was written; `substeps` is how many steps that frame took.
  void update(int frame, int substeps);
  void finish();

  static std::string formatDuration(double seconds);

 private:
  int first_, last_;
  std::FILE* stream_;
  bool interactive_;
  int lastReportedDecile_ = -1;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace msim::scene
