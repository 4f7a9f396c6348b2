// hexfem stats mesh.msh [--json]: the paper's measures of a mixed mesh.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numeric>

#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "fem/element.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/mesh_stats.hpp"

namespace hexfem {
namespace {

int run_stats(const std::string& path, bool json) {
  check_input_file(path);
  const MixedMesh mesh = read_mesh(path);
  if (mesh.num_cells() == 0) throw Error("'" + path + "' has no volume elements");
  MeshStats s = compute_stats(mesh);
  if (mesh.order == 2) {
    // The corners alone miss the curved boundary (a coarse sphere: 1 % of its volume) and a
    // cell folded between its nodes.
    const std::vector<double> volumes = element_volumes(mesh);
    s.volume = std::accumulate(volumes.begin(), volumes.end(), 0.0);
    s.solid_volumes = volume_by_solid(mesh, volumes);
    long inverted = 0;
    const auto n = static_cast<std::ptrdiff_t>(mesh.num_cells());
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : inverted)
    for (std::ptrdiff_t c = 0; c < n; ++c)
      inverted += !(element_jacobian_ratio(mesh, static_cast<std::size_t>(c)) > 0);
    s.inverted = static_cast<std::size_t>(inverted);
  }
  // The unit the file records, if any: the volume is in its cube.
  if (json) {
    nlohmann::json j = s;
    // null when the file records none (a .msh Gmsh rewrote): the key is always there.
    j["length_unit"] =
        mesh.length_unit.empty() ? nlohmann::json(nullptr) : nlohmann::json(mesh.length_unit);
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%s", stats_to_text(s).c_str());
    if (!mesh.length_unit.empty())
      std::printf("length unit      %s (recorded in the file)\n", mesh.length_unit.c_str());
  }
  return 0;
}

RegisterCommand reg{{"stats", "Element counts, H_nbr, H_vol, Q, NC, validity and volume of a mesh",
                     [](CLI::App& sub) -> std::function<int()> {
                       auto path = std::make_shared<std::string>();
                       auto json = std::make_shared<bool>(false);
                       sub.add_option("mesh", *path, "Mesh file (.msh)")->required();
                       sub.add_flag("--json", *json, "Print the measures as JSON");
                       return [path, json] { return run_stats(*path, *json); };
                     }}};

}  // namespace
}  // namespace hexfem
