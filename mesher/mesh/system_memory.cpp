#include "mesher/mesh/system_memory.hpp"

#include <fstream>
#include <string>

namespace hexfem {

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  double kb = 0;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  return 0;
}

}  // namespace hexfem
