// How much memory the machine can give this process now.
//
// Gives: the bytes available, 0 when unknown (not Linux, unreadable): MemAvailable of
// /proc/meminfo, or the memory limit of the process's control group where that is lower (a
// batch job's --mem, a container's cap: the system kills the process there, whatever the machine
// has). Used where a run would otherwise be killed half-way: the mesher's size check and the
// modal solver's choice of the direct or the iterative path.
#pragma once

#include <string>

namespace hexfem {

double available_memory_bytes();

// The lowest memory limit on the way from the process's control group up to the root (cgroup
// v2 memory.max, v1 memory.limit_in_bytes), in bytes; 0 when there is none. The paths are
// parameters for the tests: `self` lists the groups as /proc/self/cgroup does, `root` is where
// the hierarchies are mounted.
double cgroup_memory_limit(const std::string& self = "/proc/self/cgroup",
                           const std::string& root = "/sys/fs/cgroup");

}  // namespace hexfem
