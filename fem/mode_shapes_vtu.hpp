// Mode shapes for ParaView: the mesh's cells with one point-vector array per mode.
#pragma once

#include <filesystem>

#include "fem/modal_solver.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// VTK XML unstructured grid (ASCII), written atomically: points in the mesh's own units, point
// data "mode_<k>" = the k-th mode scaled to a largest nodal displacement of 1 (a shape, no unit),
// the cell data of write_vtu, field data "frequency_hz" (one value per mode).
void write_mode_shapes_vtu(const MixedMesh& mesh, const ModalResult& result,
                           const std::filesystem::path& path);

}  // namespace hexfem
