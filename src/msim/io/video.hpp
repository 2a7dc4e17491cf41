#pragma once
// MP4 assembly of rendered PNG frames with the external ffmpeg program. ffmpeg is optional: when it
// is not on PATH the encode is skipped with a note, never an error, so a run without it still
// produces its frames.
#include <filesystem>
#include <string>
#include <vector>

namespace msim::io {

struct VideoResult {
  bool written = false;
  std::string note;  // why nothing was written (ffmpeg missing or failing), empty on success
};

// Whether an executable `ffmpeg` is on PATH.
bool ffmpegAvailable();

// Encodes frames matching an ffmpeg image pattern (e.g. "frames/frame_%04d.png", numbered from 0
// or 1) into an H.264/yuv420p MP4 (odd sizes padded to even). The MP4 appears atomically.
// ffmpeg runs directly from an argument vector (no shell), so paths need no quoting.
VideoResult encodeMp4(const std::string& framePattern, double fps, const std::filesystem::path& output);

// Same for an explicit list of PNG files, in order.
VideoResult encodeMp4(const std::vector<std::filesystem::path>& frames, double fps, const std::filesystem::path& output);

}  // namespace msim::io
