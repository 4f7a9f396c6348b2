// The one error type of hexfem: a one-line message naming the problem. The CLI prints it
// as "hexfem: error: <message>" and exits non-zero; no other exception should escape.
#pragma once

#include <stdexcept>
#include <string>

namespace hexfem {

struct Error : std::runtime_error {
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A defect of the CAD model itself (a non-manifold edge, solids that overlap): no mesh size
// and no other option of ours can help, and the message must not suggest one.
struct CadError : Error {
  using Error::Error;
};

}  // namespace hexfem
