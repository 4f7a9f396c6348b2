// hexfem convert in.msh out.{msh,vtu,inp} [--binary] [--order 2]: format from the extensions (in
// any case). A .vtu of a mesh with non-conformal quad faces comes with <out>_nc.vtu, those faces
// alone. --order 2 raises an order-1 mesh (straight mid-edge nodes: a .msh has no geometry).
#include <cstdio>

#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "app/part_modal.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

struct ConvertArgs {
  std::string input, output;
  bool binary = false;
  int order = 0;  // 0: as read
};

int run_convert(const ConvertArgs& a) {
  if (a.order != 0 && a.order != 1 && a.order != 2)
    throw Error("--order must be 1 or 2 (got " + std::to_string(a.order) + ")");
  check_input_file(a.input);
  check_output_file("output", a.output, {"msh", "vtu", "inp"}, {a.input});
  check_binary_format(a.binary, a.output);
  MixedMesh mesh = read_mesh(a.input);
  if (a.order == 1 && mesh.order == 2)
    throw Error("--order 1: '" + a.input + "' is order 2 and hexfem does not lower meshes");
  if (a.order == 2 && mesh.order == 1) raise_to_order2(mesh, nullptr);
  std::vector<std::string> warnings;
  write_mesh(mesh, a.output, mesh_write_options(mesh, a.output, a.binary, &warnings));
  for (const std::string& w : warnings) std::fprintf(stderr, "hexfem: warning: %s\n", w.c_str());
  return 0;
}

RegisterCommand reg{
    {"convert", "Convert a mesh between formats (.msh in; .msh, .vtu, .inp out)",
     [](CLI::App& sub) -> std::function<int()> {
       auto a = std::make_shared<ConvertArgs>();
       sub.add_option("input", a->input, "Input mesh (.msh)")->required();
       sub.add_option("output", a->output, "Output mesh (.msh, .vtu, .inp)")->required();
       sub.add_flag("--binary", a->binary, "Write MSH 4.1 binary");
       sub.add_option("--order", a->order, "2: add straight mid-edge nodes to an order-1 mesh");
       return [a] { return run_convert(*a); };
     }}};

}  // namespace
}  // namespace hexfem
