// `hexfem recombine tets.msh -o mesh.msh [--json] [recombination options]`: the paper's
// recombination (hexes, prisms, pyramids under the conformity rules) run on tets made elsewhere,
// e.g. Gmsh's, so that recombinations and point placements can be compared on the same tets.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "app/volume_mesh_cli.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh_reports.hpp"
#include "mesher/tets_from_mesh.hpp"
#include "mesher/volume_pipeline.hpp"

namespace hexfem {
namespace {

struct RecombineArgs {
  std::string input, output;
  bool json = false, binary = false;
  VolumeOptions volume;
  std::string hex_selection = "swap-wide";
};

int run(RecombineArgs a) {
  check_input_file(a.input);
  if (!a.output.empty()) {
    check_output_file("-o", a.output, {"msh", "vtu", "inp"}, {a.input});
    check_binary_format(a.binary, a.output);
  } else if (a.binary) {
    throw Error("--binary needs an output file (-o mesh.msh)");
  }
  a.volume.hex_selection = parse_hex_selection(a.hex_selection);
  const MixedMesh tets_file = read_mesh(a.input);
  TetsFromMesh in = tets_from_mesh(tets_file);
  const std::size_t num_tets = in.tets.tets.size(), num_triangles = in.surface.mesh.num_bfaces();
  VolumeReport r;
  MixedMesh mesh = recombine_tets(std::move(in.tets), in.surface, a.volume, &r);
  mesh.length_unit = tets_file.length_unit;
  // What we emit is valid, or nothing is. Flat tets of the input stay tets (told, not refused).
  const MeshStats& st = r.stats;
  if (st.inverted > 0 || !st.watertight)
    throw Error("the recombination produced an invalid mesh (" + std::to_string(st.inverted) +
                " inverted cells, " + std::to_string(st.open_boundary_edges) +
                " open boundary edges); nothing written");
  std::vector<std::string> warnings;
  if (st.degenerate > 0)
    warnings.push_back(std::to_string(st.degenerate) +
                       " flat cell(s) (scaled Jacobian below 1e-6), tets as they were given");
  if (in.unused_nodes > 0)
    warnings.push_back(std::to_string(in.unused_nodes) +
                       " node(s) of the file in no tet, left out");
  if (!a.output.empty()) write_mesh(mesh, a.output, MeshWriteOptions{a.binary});
  if (a.json) {
    nlohmann::json j = r;
    j["file"] = a.input;
    j["input"] = {{"tets", num_tets},
                  {"boundary_triangles", num_triangles},
                  {"unused_nodes", in.unused_nodes},
                  {"turned_tets", in.turned_tets}};
    if (!a.output.empty()) j["output"] = a.output;
    j["warnings"] = warnings;
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("%s: %zu tets, %zu boundary triangles (%zu turned to positive)\n", a.input.c_str(),
              num_tets, num_triangles, in.turned_tets);
  std::printf("%s", volume_report_text(r).c_str());
  if (!a.output.empty()) std::printf("wrote %s\n", a.output.c_str());
  for (const std::string& w : warnings) std::fprintf(stderr, "hexfem: warning: %s\n", w.c_str());
  return 0;
}

RegisterCommand reg{
    {"recombine",
     "Recombine a tet mesh made elsewhere (.msh with its boundary triangles) into a hex-dominant "
     "mesh",
     [](CLI::App& sub) {
       auto a = std::make_shared<RecombineArgs>();
       sub.add_option("mesh", a->input,
                      "tet mesh (.msh): first-order tets and their boundary triangles, tagged "
                      "by surface")
           ->required();
       sub.add_option("-o,--output", a->output, "output mesh (.msh, .vtu, .inp)")
           ->check(kNonEmptyPath);
       sub.add_flag("--json", a->json, "print the report as JSON on stdout");
       sub.add_flag("--binary", a->binary, "write MSH 4.1 binary");
       add_recombination_options(sub, a->volume, a->hex_selection);
       return [a] { return run(*a); };
     }}};

}  // namespace
}  // namespace hexfem
