#include "mesher/mesh/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace hexfem {

namespace {
bool g_line_open = false;
}

bool stderr_is_terminal() {
  return ::isatty(STDERR_FILENO) == 1;
}

void show_progress(const std::string& message) {
  if (!stderr_is_terminal()) return;
  std::fprintf(stderr, "\r\033[K%s", message.c_str());
  std::fflush(stderr);
  g_line_open = true;
}

void end_progress() {
  if (!g_line_open) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  g_line_open = false;
}

}  // namespace hexfem
