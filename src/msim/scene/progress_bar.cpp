#include "msim/scene/progress_bar.hpp"

#include <unistd.h>

#include <cmath>

namespace msim::scene {

ProgressBar::ProgressBar(int firstFrame, int lastFrame, std::FILE* stream)
    : first_(firstFrame),
      last_(lastFrame),
      stream_(stream),
      interactive_(isatty(fileno(stream)) != 0),
      start_(std::chrono::steady_clock::now()) {}

std::string ProgressBar::formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const long s = std::lround(seconds);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", s / 60, s % 60);
  return buf;
}

void ProgressBar::update(int frame, int substeps) {
  const int total = last_ - first_ + 1;
  const int done = frame - first_ + 1;
  const double fraction = total > 0 ? static_cast<double>(done) / total : 1.0;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double eta = done > 0 ? elapsed / done * (total - done) : NAN;
  if (interactive_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.append(static_cast<std::size_t>(kWidth - filled), '.');
    std::fprintf(stream_, "\r  frame %d/%d [%s] %3.0f%%  substeps %d  elapsed %s  ETA %s ", frame, last_, bar.c_str(),
                 100.0 * fraction, substeps, formatDuration(elapsed).c_str(), formatDuration(eta).c_str());
    std::fflush(stream_);
    return;
  }
  const int decile = static_cast<int>(fraction * 10.0);
  if (decile != lastReportedDecile_) {
    lastReportedDecile_ = decile;
    std::fprintf(stream_, "  frame %d/%d (%3.0f%%)  substeps %d  elapsed %s  ETA %s\n", frame, last_, 100.0 * fraction,
                 substeps, formatDuration(elapsed).c_str(), formatDuration(eta).c_str());
  }
}

void ProgressBar::finish() {
  if (interactive_) std::fprintf(stream_, "\n");
  std::fflush(stream_);
}

}  // namespace msim::scene
