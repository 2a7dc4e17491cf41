#include "msim/io/video.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "msim/io/atomic_file.hpp"

extern char** environ;

namespace msim::io {

namespace {

constexpr const char* kMissingNote = "ffmpeg not found; skipped MP4";

std::optional<std::filesystem::path> findOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  std::string_view dirs(path);
  while (!dirs.empty()) {
    const std::size_t colon = dirs.find(':');
    const std::string_view dir = dirs.substr(0, colon);
    dirs = colon == std::string_view::npos ? std::string_view() : dirs.substr(colon + 1);
    const std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : dir) / program;
    std::error_code ec;
    if (std::filesystem::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

struct RunResult {
  int exitStatus = -1;
  std::string errorOutput;
};

// Runs program with args, stdin and stdout on /dev/null, and collects its stderr.
RunResult run(const std::filesystem::path& program, const std::vector<std::string>& args) {
  int pipeFds[2];
  if (::pipe2(pipeFds, O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipeFds[1], 2);

  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  pid_t pid = 0;
  const int spawnError = ::posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipeFds[1]);
  RunResult result;
  if (spawnError != 0) {
    ::close(pipeFds[0]);
    result.errorOutput = "cannot start " + program.string() + ": " + std::generic_category().message(spawnError);
    return result;
  }
  // Drain stderr before waiting so a chatty child cannot block on a full pipe.
  char buffer[4096];
  ssize_t n = 0;
  while ((n = ::read(pipeFds[0], buffer, sizeof buffer)) > 0 || (n < 0 && errno == EINTR))
    if (n > 0) result.errorOutput.append(buffer, static_cast<std::size_t>(n));
  ::close(pipeFds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exitStatus = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string formatFps(double fps) {
  char text[32];
  const auto r = std::to_chars(text, text + sizeof text, fps);
  return std::string(text, r.ptr);
}

struct RemoveOnExit {
  std::filesystem::path path;
  ~RemoveOnExit() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

struct FfmpegFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace

bool ffmpegAvailable() { return findOnPath("ffmpeg").has_value(); }

VideoResult encodeMp4(const std::string& framePattern, double fps, const std::filesystem::path& output) {
  if (!(fps > 0)) throw std::invalid_argument("encodeMp4: fps must be positive for " + output.string());
  const auto ffmpeg = findOnPath("ffmpeg");
  if (!ffmpeg) return {false, kMissingNote};
  try {
    writeFileAtomically(output, [&](const std::filesystem::path& tmp) {
      // -f mp4: the temporary name has no .mp4 extension for ffmpeg to infer the container from.
      const RunResult r = run(*ffmpeg, {"-nostdin", "-y", "-loglevel", "error", "-framerate", formatFps(fps), "-i",
                                        framePattern, "-pix_fmt", "yuv420p", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                        "-f", "mp4", tmp.string()});
      if (r.exitStatus != 0)
        throw FfmpegFailed("ffmpeg failed (exit status " + std::to_string(r.exitStatus) + ")" +
                           (r.errorOutput.empty() ? "" : ": " + r.errorOutput));
    });
  } catch (const FfmpegFailed& e) {
    return {false, e.what()};
  }
  return {true, {}};
}

VideoResult encodeMp4(const std::vector<std::filesystem::path>& frames, double fps, const std::filesystem::path& output) {
  if (frames.empty()) return {false, "no frames; skipped MP4"};
  if (!ffmpegAvailable()) return {false, kMissingNote};
  // ffmpeg reads numbered sequences most reliably, so link the frames into one under a private
  // directory instead of writing a concat list (which would need its own quoting rules).
  const std::filesystem::path linkDir = temporaryPathFor(output.string() + "-frames");
  std::filesystem::remove_all(linkDir);
  std::filesystem::create_directories(linkDir);
  const RemoveOnExit cleanup{linkDir};
  for (std::size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%08zu.png", i);
    std::filesystem::create_symlink(std::filesystem::absolute(frames[i]), linkDir / name);
  }
  return encodeMp4((linkDir / "%08d.png").string(), fps, output);
}

}  // namespace msim::io
