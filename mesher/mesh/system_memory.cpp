#include "mesher/mesh/system_memory.hpp"

#include <fstream>
#include <sstream>

namespace hexfem {

namespace {

// The lower of two limits, 0 meaning none.
double lower_limit(double a, double b) {
  return a > 0 && (b == 0 || a < b) ? a : b;
}

// The number in a limit file, or 0 for "max", a missing file or a value meaning no limit (v1
// writes 2^63 rounded down to a page).
double limit_in(const std::string& path) {
  std::ifstream in(path);
  double bytes = 0;
  if (!(in >> bytes) || !(bytes > 0) || bytes >= 1e18) return 0;
  return bytes;
}

// The lowest limit in `file` from the group at `path` up to the hierarchy's root. Inside a
// container the group's own path may not exist under the mount (its root is the container's
// group): the walk then ends at the root.
double lowest_up(const std::string& hierarchy, std::string path, const std::string& file) {
  double lowest = 0;
  while (true) {
    lowest = lower_limit(limit_in(hierarchy + (path == "/" ? "" : path) + "/" + file), lowest);
    if (path.empty() || path == "/") break;
    const auto slash = path.find_last_of('/');
    path = slash == 0 || slash == std::string::npos ? "/" : path.substr(0, slash);
  }
  return lowest;
}

}  // namespace

double cgroup_memory_limit(const std::string& self, const std::string& root) {
  std::ifstream in(self);
  std::string line;
  double lowest = 0;
  while (std::getline(in, line)) {
    // id:controllers:path; v2 is "0::path".
    const auto a = line.find(':'), b = a == std::string::npos ? a : line.find(':', a + 1);
    if (b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    if (controllers.empty()) {
      lowest = lower_limit(lowest_up(root, path, "memory.max"), lowest);
    } else {
      std::stringstream list(controllers);
      for (std::string c; std::getline(list, c, ',');)
        if (c == "memory")
          lowest = lower_limit(lowest_up(root + "/memory", path, "memory.limit_in_bytes"), lowest);
    }
  }
  return lowest;
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  double kb = 0, available = 0;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") {
      available = kb * 1024;
      break;
    }
  return lower_limit(cgroup_memory_limit(), available);
}

}  // namespace hexfem
