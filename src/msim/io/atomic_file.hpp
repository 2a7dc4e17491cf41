#pragma once
// Atomic file output: a file is written under a temporary name in the target's directory and
// renamed into place only once complete, so readers (and a rerun after a crash) never see a
// half-written frame. rename(2) within one directory is atomic on POSIX file systems.
#include <cstddef>
#include <filesystem>
#include <functional>

namespace msim::io {

// The temporary name used while `target` is being written: `.<name>.tmp-<pid>` next to it.
std::filesystem::path temporaryPathFor(const std::filesystem::path& target);

// Calls writer(tmp) and renames tmp to target once it returns. If writer throws (or the rename
// fails) the temporary file is removed, any existing target is left untouched, and the exception
// propagates. The target's directory must exist.
void writeFileAtomically(const std::filesystem::path& target,
                         const std::function<void(const std::filesystem::path& tmp)>& writer);

// Removes temporaries in `dir` left by runs that were killed mid-write: files named like
// temporaryPathFor() (files or directories) whose process id no longer exists (a live process may still be writing).
// Returns how many were removed; a missing directory counts as empty.
std::size_t removeStaleTemporaries(const std::filesystem::path& dir);

}  // namespace msim::io
