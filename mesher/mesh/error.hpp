// The one error type of hexfem: a one-line message naming the problem. The CLI prints it
// as "hexfem: error: <message>" and exits non-zero; no other exception should escape.
#pragma once

#include <stdexcept>
#include <string>

namespace hexfem {

struct Error : std::runtime_error {
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace hexfem
