#include "msim/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <stdexcept>

#include "msim/core/error.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::readBytes;
using test::scratchDir;
using test::writeText;

TEST(AtomicFile, WritesUnderTemporaryNameThenRenames) {
  const auto dir = scratchDir();
  const auto target = dir / "out.txt";
  writeFileAtomically(target, [&](const std::filesystem::path& tmp) {
    EXPECT_EQ(tmp.parent_path(), dir);
    EXPECT_NE(tmp, target);
    EXPECT_FALSE(std::filesystem::exists(target));  // not visible until complete
    writeText(tmp, "hello");
  });
  EXPECT_EQ(readBytes(target), "hello");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);  // no temporary left
}

TEST(AtomicFile, ThrowingWriterLeavesNoTemporaryAndNoTarget) {
  const auto dir = scratchDir();
  const auto target = dir / "out.txt";
  EXPECT_THROW(writeFileAtomically(target,
                                   [&](const std::filesystem::path& tmp) {
                                     writeText(tmp, "partial");
                                     throw std::runtime_error("disk full");
                                   }),
               std::runtime_error);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(AtomicFile, ThrowingWriterKeepsPreviousTarget) {
  const auto dir = scratchDir();
  const auto target = dir / "out.txt";
  writeText(target, "old");
  EXPECT_THROW(writeFileAtomically(target, [&](const std::filesystem::path&) { throw std::runtime_error("x"); }),
               std::runtime_error);
  EXPECT_EQ(readBytes(target), "old");
}

TEST(AtomicFile, RemovesOnlyTemporariesOfDeadProcesses) {
  const auto dir = scratchDir();
  // No process can have an id above the kernel's maximum (at most 2^22).
  writeText(dir / ".frame.vdb.tmp-999999999", "stale");
  std::filesystem::create_directory(dir / ".movie.mp4-frames.tmp-999999998");
  writeText(dir / ".movie.mp4-frames.tmp-999999998" / "0.png", "stale");
  const auto live = temporaryPathFor(dir / "live.vdb");  // ours: still being written
  writeText(live, "in progress");
  writeText(dir / "frame.vdb", "keep");
  writeText(dir / ".hidden.tmp-abc", "not ours");

  EXPECT_EQ(removeStaleTemporaries(dir), 2u);
  EXPECT_FALSE(std::filesystem::exists(dir / ".frame.vdb.tmp-999999999"));
  EXPECT_FALSE(std::filesystem::exists(dir / ".movie.mp4-frames.tmp-999999998"));
  EXPECT_TRUE(std::filesystem::exists(live));
  EXPECT_TRUE(std::filesystem::exists(dir / "frame.vdb"));
  EXPECT_TRUE(std::filesystem::exists(dir / ".hidden.tmp-abc"));
  EXPECT_EQ(removeStaleTemporaries(dir / "missing"), 0u);
}

}  // namespace
}  // namespace msim::io
