// The memory a run may use (mesher/mesh/system_memory.hpp): a control group's limit counts where
// it is below what the machine has. Fake hierarchies written here, the numbers read back by hand.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "mesher/mesh/system_memory.hpp"
#include "tests/support/work_dir.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  return test::fresh_work_dir("system_memory", name);
}

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// cgroup v2, as in a batch job: the job's group caps at 8 GiB, its task's group says "max", a
// group above says 64 GiB. The lowest on the way up counts.
TEST(SystemMemory, TheLowestLimitOfAGroupAndItsParentsCounts) {
  const fs::path d = fresh_dir("v2");
  write(d / "self", "0::/job_7/step_0/task_0\n");
  write(d / "root" / "job_7" / "memory.max", "8589934592\n");
  write(d / "root" / "job_7" / "step_0" / "task_0" / "memory.max", "max\n");
  write(d / "root" / "memory.max", "68719476736\n");
  EXPECT_EQ(cgroup_memory_limit((d / "self").string(), (d / "root").string()), 8589934592.0);
}

// cgroup v1 inside a container: the group's path is not under the mount, whose root holds the
// container's cap (4 GiB); "no limit" is 2^63 rounded down to a page and does not count.
TEST(SystemMemory, AVersionOneLimitAtTheMountsRootCounts) {
  const fs::path d = fresh_dir("v1");
  write(d / "self", "5:cpu,cpuacct:/x\n4:memory:/process_api/abc\n0::/\n");
  write(d / "root" / "memory" / "memory.limit_in_bytes", "4294967296\n");
  EXPECT_EQ(cgroup_memory_limit((d / "self").string(), (d / "root").string()), 4294967296.0);
  write(d / "root" / "memory" / "memory.limit_in_bytes", "9223372036854771712\n");
  EXPECT_EQ(cgroup_memory_limit((d / "self").string(), (d / "root").string()), 0.0);
}

TEST(SystemMemory, NoGroupsNoLimit) {
  const fs::path d = fresh_dir("none");
  EXPECT_EQ(cgroup_memory_limit((d / "missing").string(), (d / "root").string()), 0.0);
  // Known on Linux (/proc/meminfo).
  EXPECT_GT(available_memory_bytes(), 0.0);
}

}  // namespace
}  // namespace hexfem
