// An empty folder under the tests' work directory (HEXFEM_WORK_DIR), made afresh for one test:
// <work>/<area>/<name>, whatever an earlier run left there removed first.
#pragma once

#include <filesystem>
#include <string>

namespace hexfem::test {

inline std::filesystem::path fresh_work_dir(const std::string& area, const std::string& name) {
  const std::filesystem::path d = std::filesystem::path(HEXFEM_WORK_DIR) / area / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace hexfem::test
