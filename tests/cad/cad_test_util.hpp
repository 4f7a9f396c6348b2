// Helpers for the CAD / surface-mesher and CLI tests: test data paths, running the CLI, and
// its one-line errors.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace hexfem::cadtest {

inline std::string data(const std::string& name) {
  return std::string(HEXFEM_TEST_DATA) + "/" + name;
}
inline std::filesystem::path work(const std::string& name) {
  return std::filesystem::path(HEXFEM_WORK_DIR) / name;
}

// The whole file's bytes (empty when it cannot be read).
inline std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
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

// Runs `hexfem args` (with --json among them) and parses the JSON it prints; on failure, or with
// no JSON in the output, {"output": what it printed}. `status` gets the exit code.
inline nlohmann::json run_cli_json(const std::string& args, int* status,
                                   const std::string& env = "") {
  std::string out;
  *status = run_cli(args, &out, env);
  const auto brace = out.find('{');
  if (*status != 0 || brace == std::string::npos) return nlohmann::json{{"output", out}};
  return nlohmann::json::parse(out.substr(brace));
}

// Runs `hexfem args` and expects the one-line failure every command promises: exit 1 or 2 (not
// a signal, not CLI11's own codes), exactly one line, "hexfem: error: " first, holding `needle`.
inline void expect_one_line_error(const std::string& args, const std::string& needle) {
  std::string out;
  const int rc = run_cli(args, &out);
  EXPECT_TRUE(rc == 1 || rc == 2) << rc << " " << args;
  EXPECT_EQ(out.rfind("hexfem: error: ", 0), 0u) << out;
  EXPECT_NE(out.find(needle), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

}  // namespace hexfem::cadtest
