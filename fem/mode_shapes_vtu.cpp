#include "fem/mode_shapes_vtu.hpp"

#include <string>

#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {

void write_mode_shapes_vtu(const MixedMesh& mesh, const ModalResult& result,
                           const std::filesystem::path& path) {
  const long nn = static_cast<long>(mesh.nodes.size());
  if (result.modes.rows() != 3 * nn) throw Error("mode shapes do not match the mesh");
  VtuExtras extras;
  extras.digits = 7;
  extras.nc_faces_file = false;
  extras.field_data.emplace_back(
      "frequency_hz", std::vector<double>(result.frequencies.begin(), result.frequencies.end()));
  for (long m = 0; m < result.modes.cols(); ++m) {
    double largest = 0;
    for (long v = 0; v < nn; ++v)
      largest = std::max(largest, result.modes.block(3 * v, m, 3, 1).norm());
    const double scale = largest > 0 ? 1.0 / largest : 0.0;
    std::vector<double> shape(3 * nn);
    for (long i = 0; i < 3 * nn; ++i) shape[i] = result.modes(i, m) * scale;
    extras.point_vectors.emplace_back("mode_" + std::to_string(m + 1), std::move(shape));
  }
  write_vtu(mesh, path, extras);
}

}  // namespace hexfem
