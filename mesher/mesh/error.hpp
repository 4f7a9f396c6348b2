// The one error type of hexfem: a one-line message naming the problem. The CLI prints it
// as "hexfem: error: <message>" and exits non-zero; no other exception should escape.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace hexfem {

struct Error : std::runtime_error {
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A defect of the CAD model itself (a non-manifold edge, solids that overlap): no mesh size
// and no other option of ours can help, and the message must not suggest one.
struct CadError : Error {
  using Error::Error;
};

// A defect of the mesh on some CAD faces (the surface mesh crossing itself there, flat cells
// on them) that a finer size on those faces may remove: the pipeline tries that before it
// gives up (mesher/pipeline.cpp).
struct LocalMeshError : Error {
  LocalMeshError(const std::string& message, std::vector<int> faces, std::string defect)
      : Error(message), cad_faces(std::move(faces)), what_defect(std::move(defect)) {}
  std::vector<int> cad_faces;  // sorted, unique
  std::string what_defect;     // a few words: "flat or inverted cells", ...
};

}  // namespace hexfem
