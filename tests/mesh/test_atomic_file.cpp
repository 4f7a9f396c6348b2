// Atomic writes (issue 14 item 5): nothing half-written, no temporary file left on an error or a
// signal, no symbolic link followed, and long output names.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"
#include "tests/support/work_dir.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  return test::fresh_work_dir("atomic_file", name);
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(AtomicFile, WritesAndLeavesOnlyTheTarget) {
  const fs::path d = fresh_dir("plain");
  write_atomically(d / "a.txt", false, [](std::ostream& o) { o << std::string(200000, 'x'); });
  EXPECT_EQ(listing(d), std::vector<std::string>{"a.txt"});
  EXPECT_EQ(slurp(d / "a.txt"), std::string(200000, 'x'));
}

TEST(AtomicFile, AnErrorLeavesTheOldFileAndNoTemporary) {
  const fs::path d = fresh_dir("error");
  std::ofstream(d / "a.txt") << "old";
  EXPECT_THROW(write_atomically(d / "a.txt", false,
                                [](std::ostream& o) {
                                  o << std::string(100000, 'y');
                                  throw Error("stop");
                                }),
               Error);
  EXPECT_EQ(listing(d), std::vector<std::string>{"a.txt"});
  EXPECT_EQ(slurp(d / "a.txt"), "old");
}

TEST(AtomicFile, ADirectoryIsRefusedByName) {
  const fs::path d = fresh_dir("dir");
  fs::create_directory(d / "out.msh");
  try {
    write_atomically(d / "out.msh", false, [](std::ostream& o) { o << "x"; });
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
    // The temp file's name (".hexfem-XXXXXXXXXX.tmp") must not leak; the path itself may hold
    // "tmp".
    EXPECT_EQ(std::string(e.what()).find(".hexfem-"), std::string::npos) << e.what();
  }
  EXPECT_EQ(listing(d), std::vector<std::string>{"out.msh"});
}

// The file system allows 255 bytes per name; the temporary name must not add to the target's.
TEST(AtomicFile, A250ByteNameWorks) {
  const fs::path d = fresh_dir("long");
  const std::string name = std::string(246, 'n') + ".msh";
  write_atomically(d / name, false, [](std::ostream& o) { o << "ok"; });
  EXPECT_EQ(listing(d), std::vector<std::string>{name});
}

// Runs `body` in a child process and returns its wait status.
template <class F>
int in_child(F body) {
  const pid_t pid = fork();
  if (pid == 0) {
    body();
    _exit(0);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

// A link planted where the old code put its temporary file (<out>.tmp.<pid>) must not be
// followed: its target stays as it was.
TEST(AtomicFile, NeverFollowsAPlantedLink) {
  const fs::path d = fresh_dir("link");
  std::ofstream(d / "victim") << "precious";
  const int status = in_child([&] {
    fs::create_symlink(d / "victim", d / ("out.msh.tmp." + std::to_string(getpid())));
    write_atomically(d / "out.msh", false, [](std::ostream& o) { o << "mesh"; });
  });
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_EQ(slurp(d / "victim"), "precious");
  EXPECT_EQ(slurp(d / "out.msh"), "mesh");
}

// SIGINT or SIGTERM in the middle of a write: the process dies of that signal and leaves
// neither the target nor a temporary file.
TEST(AtomicFile, ASignalRemovesTheTemporaryFile) {
  for (int sig : {SIGINT, SIGTERM}) {
    const fs::path d = fresh_dir("signal" + std::to_string(sig));
    const int status = in_child([&] {
      write_atomically(d / "out.msh", false, [&](std::ostream& o) {
        o << std::string(1 << 20, 'z');
        o.flush();
        raise(sig);
      });
    });
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;
    EXPECT_TRUE(listing(d).empty()) << listing(d).front();
  }
}

}  // namespace
}  // namespace hexfem
