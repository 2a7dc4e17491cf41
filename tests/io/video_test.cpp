#include "msim/io/video.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

#include "msim/io/png.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::scratchDir;

std::vector<std::filesystem::path> writeFrames(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> frames;
  for (int f = 0; f < 3; ++f) {
    Image image(15, 9);  // odd size exercises the padding filter
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = static_cast<std::uint8_t>(i * 3 + f * 80);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", f);
    frames.push_back(dir / name);
    writePng(frames.back(), image);
  }
  return frames;
}

TEST(Video, EncodesPatternAndFileList) {
  if (!ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not installed";
  const auto dir = scratchDir();
  const auto frames = writeFrames(dir);
  const VideoResult fromPattern = encodeMp4((dir / "frame_%04d.png").string(), 24, dir / "pattern.mp4");
  EXPECT_TRUE(fromPattern.written) << fromPattern.note;
  EXPECT_GT(std::filesystem::file_size(dir / "pattern.mp4"), 0u);
  const VideoResult fromList = encodeMp4(frames, 12.5, dir / "list.mp4");
  EXPECT_TRUE(fromList.written) << fromList.note;
  EXPECT_GT(std::filesystem::file_size(dir / "list.mp4"), 0u);
  // Only the frames and the two videos: no temporaries or link directories remain.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 5);
}

TEST(Video, FailingEncodeReportsAndLeavesNoFile) {
  if (!ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not installed";
  const auto dir = scratchDir();
  const VideoResult r = encodeMp4((dir / "none_%04d.png").string(), 24, dir / "out.mp4");
  EXPECT_FALSE(r.written);
  EXPECT_NE(r.note.find("ffmpeg failed"), std::string::npos) << r.note;
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(Video, MissingFfmpegIsSkippedNotAnError) {
  const auto dir = scratchDir();
  const auto frames = writeFrames(dir);
  const std::string savedPath = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", (dir / "empty-bin").c_str(), 1);
  const bool available = ffmpegAvailable();
  const VideoResult r = encodeMp4(frames, 24, dir / "out.mp4");
  ::setenv("PATH", savedPath.c_str(), 1);
  EXPECT_FALSE(available);
  EXPECT_FALSE(r.written);
  EXPECT_EQ(r.note, "ffmpeg not found; skipped MP4");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.mp4"));
}

}  // namespace
}  // namespace msim::io
