// Helpers for the CAD / surface-mesher tests: test data paths and running the CLI.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace hexfem::cadtest {

inline std::string data(const std::string& name) {
  return std::string(HEXFEM_TEST_DATA) + "/" + name;
}
inline std::filesystem::path work(const std::string& name) {
  return std::filesystem::path(HEXFEM_WORK_DIR) / name;
}

// Runs `hexfem args` with stderr merged into stdout, with `env` ("NAME=value ...") set;
// returns the exit code.
inline int run_cli(const std::string& args, std::string* out, const std::string& env = "") {
  const std::string cmd =
      (env.empty() ? "" : "env " + env + " ") + std::string(HEXFEM_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  std::array<char, 4096> buf;
  out->clear();
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out->append(buf.data(), n);
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace hexfem::cadtest
