#include "msim/io/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <string>
#include <system_error>

namespace msim::io {

namespace {

constexpr std::string_view kTmpMarker = ".tmp-";

// The process id encoded in a temporary's file name, or -1 when the name is not one of ours.
long temporaryOwnerPid(const std::string& name) {
  if (name.size() < 2 || name[0] != '.') return -1;
  const std::size_t marker = name.rfind(kTmpMarker);
  if (marker == std::string::npos || marker < 2) return -1;
  const char* first = name.data() + marker + kTmpMarker.size();
  const char* last = name.data() + name.size();
  long pid = -1;
  const auto [end, ec] = std::from_chars(first, last, pid);
  if (ec != std::errc() || end != last || first == last || pid <= 0) return -1;
  return pid;
}

bool processExists(long pid) {
  // kill with signal 0 only checks existence; EPERM means it exists but belongs to someone else.
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

}  // namespace

std::filesystem::path temporaryPathFor(const std::filesystem::path& target) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) about `"." + std::string`.
  std::string name(1, '.');
  name += target.filename().string();
  name += kTmpMarker;
  name += std::to_string(::getpid());
  return target.parent_path() / name;
}

void writeFileAtomically(const std::filesystem::path& target,
                         const std::function<void(const std::filesystem::path& tmp)>& writer) {
  const std::filesystem::path tmp = temporaryPathFor(target);
  try {
    writer(tmp);
    std::filesystem::rename(tmp, target);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
}

std::size_t removeStaleTemporaries(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec);
  if (ec) return 0;
  std::size_t removed = 0;
  for (const auto& entry : it) {
    const long pid = temporaryOwnerPid(entry.path().filename().string());
    if (pid < 0 || processExists(pid)) continue;
    // remove_all: some writers (video frame links) use a temporary directory, not a file.
    if (std::filesystem::remove_all(entry.path(), ec) > 0) ++removed;
  }
  return removed;
}

}  // namespace msim::io
