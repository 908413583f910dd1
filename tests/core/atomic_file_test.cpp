// AtomicFile: a target is only ever the old file or the whole new one, and no temporary outlives its
// writer (error, signal, or SIGKILL followed by the next write).
#include "core/atomic_file.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace fs = std::filesystem;

namespace rtr {
namespace {

struct AtomicFileTest : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_atomic_" + std::to_string(::getpid()));
  fs::path target = dir / "out.bin";
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  static std::string read(const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  // A temporary such as a writer that was SIGKILLed leaves: named for a process that no longer exists.
  fs::path deadWritersTemporary() {
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ::waitpid(child, nullptr, 0);
    const fs::path p = dir / (".out.bin.rtrtmp-" + std::to_string(child) + "-abcdef");
    std::ofstream(p) << "half a file";
    return p;
  }
};

TEST_F(AtomicFileTest, WritesAndReplacesLeavingOnlyTheTarget) {
  writeFileAtomic(target, "first");
  writeFileAtomic(target, "second");
  EXPECT_EQ(read(target), "second");
  EXPECT_EQ(names(), std::vector<std::string>{"out.bin"});
}

TEST_F(AtomicFileTest, EachWriterHasItsOwnTemporary) {
  AtomicFile a(target), b(target);
  EXPECT_NE(a.temporary(), b.temporary());
  EXPECT_EQ(a.temporary().parent_path(), dir);
  EXPECT_NE(a.temporary().filename().string().find(std::to_string(::getpid())), std::string::npos);
  a.write("aaaa", 4);
  b.write("bb", 2);
  a.commit();
  b.commit();
  EXPECT_EQ(read(target), "bb");
  EXPECT_EQ(names(), std::vector<std::string>{"out.bin"});
}

TEST_F(AtomicFileTest, UncommittedWriteLeavesTheOldFileAndNoTemporary) {
  writeFileAtomic(target, "old");
  {
    AtomicFile f(target);
    f.write("new but abandoned", 17);
  }  // an exception between write and commit ends here
  EXPECT_EQ(read(target), "old");
  EXPECT_EQ(names(), std::vector<std::string>{"out.bin"});
}

TEST_F(AtomicFileTest, WithoutReplaceAnExistingTargetIsKept) {
  writeFileAtomic(target, "old");
  EXPECT_THROW(writeFileAtomic(target, "new", Replace::No), OutputExists);
  EXPECT_EQ(read(target), "old");
  EXPECT_EQ(names(), std::vector<std::string>{"out.bin"});
  fs::remove(target);
  writeFileAtomic(target, "new", Replace::No);
  EXPECT_EQ(read(target), "new");
}

TEST_F(AtomicFileTest, OfTwoCreatorsExactlyOneWins) {
  AtomicFile a(target), b(target);
  a.write("a", 1);
  b.write("b", 1);
  a.commit(Replace::No);
  EXPECT_THROW(b.commit(Replace::No), OutputExists);
  EXPECT_EQ(read(target), "a");
}

TEST_F(AtomicFileTest, NextWriteRemovesWhatAKilledWriterLeftButNotALiveOnes) {
  const fs::path stale = deadWritersTemporary();
  const fs::path live = dir / (".out.bin.rtrtmp-" + std::to_string(::getppid()) + "-abcdef");
  std::ofstream(live) << "a running writer's";
  const fs::path other = dir / ".other.bin.rtrtmp-999999999-abcdef";
  std::ofstream(other) << "another target's";
  writeFileAtomic(target, "x");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_EQ(read(target), "x");
}

TEST_F(AtomicFileTest, SigtermRemovesTheTemporary) {
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    AtomicFile f(target);
    f.write("partial", 7);
    (void)!::write(ready[1], "r", 1);
    ::pause();
    ::_exit(0);
  }
  char c;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  EXPECT_EQ(names().size(), 1u);  // the temporary exists while the writer runs
  ::kill(child, SIGTERM);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);  // still dies of the signal
  EXPECT_TRUE(names().empty());
  ::close(ready[0]);
  ::close(ready[1]);
}

TEST_F(AtomicFileTest, CopyKeepsTheBytes) {
  writeFileAtomic(dir / "src", std::string(200000, 'q') + "end");
  copyFileAtomic(dir / "src", target, Replace::No);
  EXPECT_EQ(read(target), read(dir / "src"));
  EXPECT_THROW(copyFileAtomic(dir / "src", target, Replace::No), OutputExists);
  EXPECT_THROW(copyFileAtomic(dir / "missing", dir / "t2", Replace::Yes), Error);
  EXPECT_FALSE(fs::exists(dir / "t2"));
}

TEST_F(AtomicFileTest, MissingFolderIsAnErrorNamingTheTarget) {
  try {
    writeFileAtomic(dir / "nowhere/out.bin", "x");
    FAIL() << "no error";
  } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find("nowhere/out.bin"), std::string::npos) << e.what(); }
}

}  // namespace
}  // namespace rtr
