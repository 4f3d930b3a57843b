// AtomicFile: files appear whole under their final name or not at all, and no temporary file
// outlives an AtomicFile that was not committed.

#include <filesystem>

#include <unistd.h>

#include <gtest/gtest.h>

#include <sph/core/error.h>
#include <sph/io/atomic_file.h>

#include "support/temp_dir.h"

namespace sph {
namespace {

namespace fs = std::filesystem;
using test::entries;
using test::slurp;
using test::spit;
using test::TempDir;

TEST(AtomicFile, NothingVisibleUnderTheFinalNameBeforeCommit) {
  TempDir dir;
  const fs::path target = dir / "data.txt";
  {
    AtomicFile f(target);
    f.write("hello ");
    f.stream() << "world";
    f.stream().flush();  // even flushed bytes stay under the temporary name
    EXPECT_FALSE(fs::exists(target));
    const auto names = entries(dir.path());
    ASSERT_EQ(names.size(), 1u);
    EXPECT_EQ(names[0].front(), '.') << "temporary name should be hidden: " << names[0];
    EXPECT_NE(names[0], "data.txt");
    f.commit();
    EXPECT_TRUE(fs::exists(target));
  }
  EXPECT_EQ(slurp(target), "hello world");
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"data.txt"});
}

TEST(AtomicFile, UncommittedLeavesNoTemporaryFileBehind) {
  TempDir dir;
  {
    AtomicFile f(dir / "never.txt");
    f.write("discarded");
    EXPECT_EQ(entries(dir.path()).size(), 1u);  // the temporary file exists while writing
  }
  EXPECT_TRUE(entries(dir.path()).empty());
}

TEST(AtomicFile, UncommittedDoesNotTouchAnExistingFile) {
  TempDir dir;
  const fs::path target = dir / "keep.txt";
  spit(target, "old content");
  {
    AtomicFile f(target);
    f.write("new content that is never committed");
  }
  EXPECT_EQ(slurp(target), "old content");
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicFile, WriteFileAtomicReplacesAnExistingFile) {
  TempDir dir;
  const fs::path target = dir / "summary.json";
  spit(target, "a much longer old content than the new one\n");
  write_file_atomic(target, "new\n");
  EXPECT_EQ(slurp(target), "new\n");
  write_file_atomic(target, std::string("bin\0ary", 7));
  EXPECT_EQ(slurp(target), std::string("bin\0ary", 7));
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"summary.json"});
}

TEST(AtomicFile, TwoOpenAtOnceForTheSameTargetUseDistinctTemporaries) {
  TempDir dir;
  const fs::path target = dir / "x.txt";
  AtomicFile a(target), b(target);
  a.write("a");
  b.write("b");
  EXPECT_EQ(entries(dir.path()).size(), 2u);
  a.commit();
  b.commit();
  EXPECT_EQ(slurp(target), "b");
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"x.txt"});
}

TEST(AtomicFile, CommitOntoADirectoryThrowsSphErrorAndCleansUp) {
  TempDir dir;
  const fs::path target = dir / "occupied";
  fs::create_directory(target);
  spit(target / "inside.txt", "x");
  {
    AtomicFile f(target);
    f.write("data");
    EXPECT_THROW(f.commit(), Error);
  }
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"occupied"}) << "no temporary left behind";
  EXPECT_EQ(slurp(target / "inside.txt"), "x");
}

TEST(AtomicFile, NonExistentDirectoryThrowsSphError) {
  TempDir dir;
  const fs::path target = dir / "no" / "such" / "dir" / "f.txt";
  EXPECT_THROW({ AtomicFile f(target); }, Error);
  EXPECT_THROW(write_file_atomic(target, "x"), Error);
  try {
    AtomicFile f(target);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "no" / "such" / "dir").string()), std::string::npos)
        << "the message should name the directory: " << e.what();
    // The cause, not a guess at permissions (it said "is it writable?").
    EXPECT_EQ(e.message(), "the directory does not exist; create it first, or write the file into an existing one");
  }
  EXPECT_TRUE(entries(dir.path()).empty());
}

TEST(AtomicFile, ParentThatIsARegularFileThrowsSphError) {
  TempDir dir;
  spit(dir / "file", "x");
  EXPECT_THROW({ AtomicFile f(dir / "file" / "f.txt"); }, Error);
  try {
    AtomicFile f(dir / "file" / "f.txt");
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), (dir / "file").string());
    EXPECT_EQ(e.message(), "is not a directory; expected a directory to hold the file");
  }
}

TEST(AtomicFile, ReadOnlyDirectoryThrowsSphError) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions do not block writes";
  TempDir dir;
  const fs::path ro = dir / "ro";
  fs::create_directory(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW({ AtomicFile f(ro / "f.txt"); }, Error);
  EXPECT_THROW(write_file_atomic(ro / "f.txt", "x"), Error);
  fs::permissions(ro, fs::perms::owner_all);
  EXPECT_TRUE(entries(ro).empty());
}

TEST(AtomicFile, UnwritableDirectoryThrowsSphErrorEvenForRoot) {
  // procfs refuses new files for every user, root included.
  if (!fs::is_directory("/proc/self")) GTEST_SKIP() << "no /proc";
  EXPECT_THROW({ AtomicFile f("/proc/sph_atomic_file_test.txt"); }, Error);
}

}  // namespace
}  // namespace sph
